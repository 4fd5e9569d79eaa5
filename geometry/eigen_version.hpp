#pragma once
// The version of Eigen the geometry module was built with, for `diefill --version` (beside
// mesh/versions.hpp's libraries).
#include <string>

namespace geometry {
std::string eigen_version();
}  // namespace geometry
