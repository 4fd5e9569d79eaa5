#include "core/resources.hpp"

#include <cstdlib>
#include <system_error>

namespace diefill {

namespace fs = std::filesystem;

fs::path resource_path(std::string_view relative) {
  if (const char* data = std::getenv("DIEFILL_DATA_DIR"); data && *data) return fs::path(data) / relative;
  std::error_code error;
  const fs::path executable = fs::read_symlink("/proc/self/exe", error);
  if (!error) {
    const fs::path installed = executable.parent_path().parent_path() / "share" / "diefill" / relative;
    if (fs::exists(installed)) return installed;
  }
  return fs::path(DIEFILL_SOURCE_DIR) / relative;
}

}  // namespace diefill
