#include "pipeline/pictures.hpp"

#include <fmt/core.h>

#include <cstdlib>

#include "core/log.hpp"
#include "core/resources.hpp"

namespace pipeline {

void draw_pictures(const std::vector<std::string>& arguments) {
  const std::filesystem::path script = diefill::resource_path("postprocess/plots.py");
  std::string command = fmt::format("/usr/bin/python3 '{}'", script.string());
  for (const std::string& a : arguments) command += fmt::format(" '{}'", a);
  command += " 2>&1";
  if (std::system(command.c_str()) != 0)
    diefill::log::warn("the pictures were not drawn ({} failed); install python3-matplotlib (scripts/setup.sh does)", script.string());
}

}  // namespace pipeline
