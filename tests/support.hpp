#pragma once
// Helpers shared by the tests: temporary folders, running the diefill executable, test meshes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>
#include <sys/wait.h>
#include <unistd.h>

namespace test {

namespace fs = std::filesystem;

// A fresh folder under the system temporary directory, removed with the object.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string("diefill-") + (info ? info->test_suite_name() : "x") + "-" +
                       (info ? info->name() : "y") + "-" + std::to_string(::getpid());
    for (char& c : name)
      if (c == '/') c = '_';
    path_ = fs::temp_directory_path() / name;
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  const fs::path& path() const { return path_; }
  fs::path operator/(const std::string& leaf) const { return path_ / leaf; }

 private:
  fs::path path_;
};

struct Run {
  int status = -1;     // exit status
  std::string output;  // stdout and stderr together
};

// A folder under the system temporary directory for a whole suite's runs, emptied when the
// process first asks for it and kept afterwards (runs share its caches; a failure leaves them to
// read): diefill-NAME-<pid>.
inline fs::path suite_folder(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("diefill-" + name + "-" + std::to_string(::getpid()));
  static std::vector<fs::path> emptied;
  if (std::find(emptied.begin(), emptied.end(), p) == emptied.end()) {
    fs::remove_all(p);
    emptied.push_back(p);
  }
  return p;
}

// Runs a shell command line and collects what it prints.
inline Run run_command(const std::string& command) {
  Run run;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return run;
  char buffer[4096];
  while (std::size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) run.output.append(buffer, n);
  const int raw = ::pclose(pipe);
  run.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
  return run;
}

// Runs the diefill executable with `arguments` (a shell-quoted string).
inline Run run_diefill(const std::string& arguments) {
  return run_command(std::string(DIEFILL_EXECUTABLE) + " " + arguments + " 2>&1");
}

inline void write_text(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

inline std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline fs::path shared_meshes() { return DIEFILL_SHARED_MESHES; }
inline fs::path source_dir() { return DIEFILL_SOURCE_DIR; }

// Where the shared meshes are missing, a developer's checkout skips the tests that need them;
// CI (DIEFILL_REQUIRE_SHARED=1, set by .ci/run) has them, so there a missing folder is a broken
// path and fails the test instead of hiding it behind a skip.
inline bool shared_meshes_required() {
  const char* flag = std::getenv("DIEFILL_REQUIRE_SHARED");
  return flag && *flag && std::string(flag) != "0";
}

#define REQUIRE_SHARED_MESHES()                                                                   \
  if (!std::filesystem::exists(test::shared_meshes() / "dies")) {                                \
    if (test::shared_meshes_required())                                                           \
      GTEST_FAIL() << "shared meshes not found at " << test::shared_meshes()                      \
                   << ", and DIEFILL_REQUIRE_SHARED is set";                                      \
    GTEST_SKIP() << "shared meshes not found at " << test::shared_meshes()                        \
                 << " (configure with -DDIEFILL_SHARED_MESHES=...)";                              \
  }

}  // namespace test
