#include <fmt/core.h>

#include "cli/commands.hpp"
#include "core/resources.hpp"
#include "geometry/eigen_version.hpp"
#include "mesh/versions.hpp"

namespace cli {

std::string version_text() {
  return fmt::format(
      "diefill {}\n  CGAL {}\n  OpenVDB {}\n  assimp {}\n  Embree {}\n  Eigen {}\n  data: {}", DIEFILL_VERSION,
      mesh::cgal_version(), mesh::openvdb_version(), mesh::assimp_version(), mesh::embree_version(),
      geometry::eigen_version(), diefill::resource_path("").string());
}

}  // namespace cli
