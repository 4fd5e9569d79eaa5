#pragma once
// A grain shape's clump template from its mesh file: import, repair within a tenth of the clump
// tolerance, then the greedy sphere choice (mesh/clump.hpp). Shared by `diefill clump` and the
// pipeline's `powder.shape`.
#include <cstdint>
#include <filesystem>

#include "geometry/trimesh.hpp"
#include "mesh/clump.hpp"

namespace pipeline {

struct ClumpRequest {
  std::filesystem::path mesh;
  geometry::LengthUnit unit = geometry::LengthUnit::mm;
  double tolerance = 0.05;
  int max_spheres = 64;
  std::uint64_t seed = 1;
};

// Throws InputError for a mesh that cannot be repaired or a tolerance the spheres cannot meet.
geometry::ClumpTemplate build_clump(const ClumpRequest& request);

// `diefill clump`'s outputs: the template (JSON) at `out` when it ends in .json, else in the
// folder `out` named after the mesh; beside it NAME_errors.csv, the errors and the relative cost
// of a step against the number of spheres, and its chart. Returns the template's path.
std::filesystem::path write_clump_outputs(const geometry::ClumpTemplate& clump, const std::filesystem::path& mesh,
                                          const std::filesystem::path& out);

}  // namespace pipeline
