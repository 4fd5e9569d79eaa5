#pragma once
// Multi-sphere clump templates of irregular grains (docs/ARCHITECTURE.md, "Grains": clumps are templates plus
// instances). A template is built once per grain shape: the spheres, in the grain's principal
// frame, plus the real grain's volume and principal moments, so that a simulation gives the
// clump the mass and inertia of the grain rather than of the overlapping spheres.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "geometry/clump_template.hpp"
#include "geometry/trimesh.hpp"

namespace mesh {

// Volume, centroid and inertia of a solid of unit density bounded by a closed, outward mesh.
struct MassProperties {
  double volume = 0.0;                                            // [m³]
  geometry::Vec3 centroid = geometry::Vec3::Zero();               // [m]
  Eigen::Matrix3d inertia_per_density = Eigen::Matrix3d::Zero();  // about the centroid [m⁵]
};

// Exact polyhedral integrals (Eberly, "Polyhedral Mass Properties (Revisited)", 2002): no
// sampling, exact up to rounding for any closed, outward triangle mesh.
MassProperties mass_properties(const geometry::TriMesh& closed_outward_mesh);

struct ClumpOptions {
  double tolerance = 0.05;  // both relative errors must reach it
  int max_spheres = 64;
  std::uint64_t seed = 1;  // surface sampling; same seed and mesh give the same template
  int samples = 150000;    // grid nodes over the grain's bounding box (at least 1000), for the
                           // volume estimate
};

// Greedy sphere selection until the volume and Hausdorff errors both reach the tolerance.
// Throws diefill::InputError for a mesh that is not closed and outward oriented (run repair
// first), and when max_spheres spheres cannot reach the tolerance (the message says how far
// they got).
geometry::ClumpTemplate make_clump(const geometry::TriMesh& grain, const ClumpOptions& options);

// The template as JSON (docs/INTERFACE.md, "Clump template").
std::string clump_json(const geometry::ClumpTemplate& clump);

}  // namespace mesh
