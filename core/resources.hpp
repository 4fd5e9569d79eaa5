#pragma once
// Files diefill reads at run time (the plotting script, the bundled dies), found beside the
// executable when it is installed (<prefix>/share/diefill/), else in the source tree it was
// built from; DIEFILL_DATA_DIR overrides both.
#include <filesystem>
#include <string_view>

namespace diefill {

// `relative` as laid out in the source tree ("postprocess/plots.py", "dies/ring.stl").
std::filesystem::path resource_path(std::string_view relative);

}  // namespace diefill
