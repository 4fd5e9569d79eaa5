#pragma once
// `diefill sdf --verify N`: an SDF against the exact (Embree) distance of the mesh it came from.
#include <cstdint>

#include "geometry/wall_field.hpp"
#include "mesh/exact.hpp"
#include "mesh/sdf.hpp"

namespace mesh {

struct SdfErrors {
  double max_voxels = 0;         // max |SDF - exact| over all samples, in voxels
  double mean_voxels = 0;
  double max_smooth_voxels = 0;  // over samples farther than one voxel from a sharp edge
  geometry::Vec3 worst_smooth_point = geometry::Vec3::Zero();  // where that maximum occurs [m]
  std::size_t sign_disagreements = 0;      // among samples with |exact| > 0.5 voxel
  geometry::Vec3 first_sign_disagreement = geometry::Vec3::Zero();  // where the first one lies [m]
};

struct SdfVerification {
  std::size_t samples = 0;         // points in the band (all 8 trilinear corners active)
  std::size_t smooth_samples = 0;  // samples farther than one voxel from a sharp edge
  std::size_t sign_checked = 0;    // samples with |exact| > 0.5 voxel
  std::size_t reachable_samples = 0;  // samples outside or less than a voxel inside the solid
  SdfErrors query;                 // the simulation's wall query (WallField::signed_distance): its
                                   // errors over the reachable samples, its signs over all
  SdfErrors grid;                  // plain trilinear interpolation of the .vdb grid
  // Beside the sharp edges, where uniform samples seldom land and a wrong sign does harm: as many
  // points again within two voxels of a random point of a sharp edge (uniform along the edges),
  // the query's sign and the signs of its wall contacts within two voxels (local_minima)
  // against the exact one, where |exact| > 0.5 voxel.
  std::size_t sharp_samples = 0;
  std::size_t sharp_sign_disagreements = 0;
  std::size_t sharp_contact_sign_disagreements = 0;
  geometry::Vec3 first_sharp_disagreement = geometry::Vec3::Zero();
};

// `samples` uniformly random points in the band, reproducible from `seed`; sharp edges are
// those whose faces meet at more than `sharp_angle_deg`.
SdfVerification verify_sdf(const geometry::WallField& field, const geometry::TriMesh& mesh, const ExactSurface& exact,
                           std::size_t samples, std::uint64_t seed, double sharp_angle_deg = 30.0);

}  // namespace mesh
