#pragma once
// Outputs are written under a temporary name and renamed when complete, so that a failed run
// never leaves a partial file behind and never destroys a user's earlier result.
#include <filesystem>
#include <string_view>

namespace diefill {

// A temporary path beside `target` (same directory, so that rename is atomic).
std::filesystem::path temporary_sibling(const std::filesystem::path& target);

// Writes `content` to `target` atomically; creates parent directories.
void write_file_atomic(const std::filesystem::path& target, std::string_view content);

// Owns a temporary sibling of `target`: the writer fills `path()`, then `commit()` renames it
// into place. Destroyed without commit, it removes the temporary file.
class PendingFile {
 public:
  explicit PendingFile(std::filesystem::path target);
  ~PendingFile();
  PendingFile(const PendingFile&) = delete;
  PendingFile& operator=(const PendingFile&) = delete;
  const std::filesystem::path& path() const { return temporary_; }
  void commit();

 private:
  std::filesystem::path target_, temporary_;
  bool committed_ = false;
};

// A folder of outputs that appear together or not at all: files are written into a hidden
// staging folder inside `target`, and commit() moves them into `target` (replacing earlier
// versions); destroyed without commit, the staging folder is removed and `target` is as before.
class StagingFolder {
 public:
  explicit StagingFolder(std::filesystem::path target);
  ~StagingFolder();
  StagingFolder(const StagingFolder&) = delete;
  StagingFolder& operator=(const StagingFolder&) = delete;
  std::filesystem::path operator/(const std::string& name) const { return staging_ / name; }
  const std::filesystem::path& path() const { return staging_; }
  void commit();

 private:
  std::filesystem::path target_, staging_;
  bool committed_ = false;
};

}  // namespace diefill
