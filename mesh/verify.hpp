#pragma once
// `diefill sdf --verify N`: an SDF against the exact (Embree) distance of the mesh it came from.
#include <cstdint>

#include "mesh/exact.hpp"
#include "mesh/sdf.hpp"

namespace mesh {

struct SdfVerification {
  std::size_t samples = 0;            // points inside the band (all 8 trilinear corners active)
  double max_error_voxels = 0;        // max |SDF - exact| over all samples, in voxels
  double mean_error_voxels = 0;
  std::size_t smooth_samples = 0;     // samples farther than one voxel from a sharp edge
  double max_error_smooth_voxels = 0; // max error over those
  Vec3 worst_smooth_point = Vec3::Zero();  // where that maximum occurs [m]
  std::size_t sign_checked = 0;       // samples with |exact| > 0.5 voxel
  std::size_t sign_disagreements = 0; // among those, the SDF's sign differs from the exact one
};

// `samples` uniformly random points in the band, reproducible from `seed`; sharp edges are
// those whose faces meet at more than `sharp_angle_deg`.
SdfVerification verify_sdf(const SdfGrid& sdf, const TriMesh& mesh, const ExactSurface& exact,
                           std::size_t samples, std::uint64_t seed, double sharp_angle_deg = 30.0);

}  // namespace mesh
