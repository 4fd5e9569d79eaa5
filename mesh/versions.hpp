#pragma once
// Versions of the libraries the mesh module was built with, for `diefill --version`; each is
// defined in the one translation unit that includes that library.
#include <string>

namespace mesh {
std::string assimp_version();
std::string cgal_version();
std::string openvdb_version();
std::string embree_version();
}  // namespace mesh
