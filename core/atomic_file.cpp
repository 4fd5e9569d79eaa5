#include "core/atomic_file.hpp"

#include <unistd.h>

#include <atomic>
#include <fstream>
#include <string>

#include "core/error.hpp"

namespace diefill {

namespace fs = std::filesystem;

fs::path temporary_sibling(const fs::path& target) {
  static std::atomic<unsigned> counter{0};
  fs::path tmp = target;
  tmp += ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
  return tmp;
}

void write_file_atomic(const fs::path& target, std::string_view content) {
  PendingFile pending(target);
  {
    std::ofstream out(pending.path(), std::ios::binary);
    out.write(content.data(), std::streamsize(content.size()));
    if (!out)
      throw InputError(target.string(), "", "cannot be written",
                       "Check that the output folder is writable and the disk is not full");
  }
  pending.commit();
}

PendingFile::PendingFile(fs::path target) : target_(std::move(target)) {
  if (target_.has_parent_path()) {
    std::error_code ec;
    fs::create_directories(target_.parent_path(), ec);
    if (ec)
      throw InputError(target_.parent_path().string(), "", "cannot create the output folder (" +
                           ec.message() + ")",
                       "Choose an output folder you can write to");
  }
  temporary_ = temporary_sibling(target_);
}

PendingFile::~PendingFile() {
  if (!committed_) {
    std::error_code ec;
    fs::remove(temporary_, ec);
  }
}

void PendingFile::commit() {
  std::error_code ec;
  fs::rename(temporary_, target_, ec);
  if (ec)
    throw InputError(target_.string(), "", "cannot be written (" + ec.message() + ")",
                     "Check that the output folder is writable");
  committed_ = true;
}

StagingFolder::StagingFolder(fs::path target) : target_(std::move(target)) {
  staging_ = target_ / (".staging-" + std::to_string(::getpid()));
  std::error_code ec;
  fs::remove_all(staging_, ec);
  fs::create_directories(staging_, ec);
  if (ec)
    throw InputError(target_.string(), "", "cannot create the output folder (" + ec.message() + ")",
                     "Choose an output folder you can write to");
}

StagingFolder::~StagingFolder() {
  std::error_code ec;
  fs::remove_all(staging_, ec);
}

void StagingFolder::commit() {
  for (const auto& entry : fs::directory_iterator(staging_)) {
    std::error_code ec;
    const fs::path target = target_ / entry.path().filename();
    // A folder (fem/) replaces the earlier one whole: none of the earlier run's files stays in it.
    // Renamed aside first, since a folder cannot be renamed onto a folder that holds files.
    const fs::path aside = target_ / (".replaced-" + entry.path().filename().string());
    const bool replace_folder = entry.is_directory() && fs::is_directory(target);
    if (replace_folder) {
      fs::remove_all(aside, ec);
      fs::rename(target, aside, ec);
    }
    if (!ec) fs::rename(entry.path(), target, ec);
    if (ec)
      throw InputError((target_ / entry.path().filename()).string(), "", "cannot be written (" + ec.message() + ")",
                       "Check that the output folder is writable");
    if (replace_folder) fs::remove_all(aside, ec);  // the new one is in place: a leftover costs only space
  }
  committed_ = true;
}

}  // namespace diefill
