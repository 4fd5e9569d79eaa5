#pragma once
// The version of Eigen the geometry module was built with, for `diefill --version` (beside
// mesh/versions.hpp's libraries); defined in trimesh.cpp.
#include <string>

namespace geometry {
std::string eigen_version();
}  // namespace geometry
