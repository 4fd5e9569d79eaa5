#pragma once
// A multi-sphere clump template as plain data (docs/ARCHITECTURE.md, "Grains": templates plus instances),
// in the small geometry target that the DEM links: the spheres in the grain's principal frame,
// the real grain's volume and principal moments, and the approximation's errors. mesh/clump.hpp
// builds one from a grain mesh.
#include <Eigen/Core>
#include <vector>

#include "geometry/trimesh.hpp"

namespace geometry {

struct ClumpSphere {
  Vec3 centre;    // [m], principal frame
  double radius;  // [m]
};

// The errors after a given number of spheres: the curve from which a user picks a count.
struct ClumpStep {
  int spheres = 0;
  double volume_error = 0.0;     // |V_union − V_mesh| / V_mesh
  double hausdorff_error = 0.0;  // two-sided surface distance / equivalent diameter
};

struct ClumpTemplate {
  // Principal frame: origin at the mesh centroid, axes the principal axes of inertia sorted by
  // ascending moment; p_principal = rotation_mesh_to_principal · (p_mesh − mesh_centroid).
  std::vector<ClumpSphere> spheres;
  double mesh_volume_m3 = 0.0;
  Vec3 inertia_principal_per_density = Vec3::Zero();  // ascending [m⁵]
  Eigen::Matrix3d rotation_mesh_to_principal = Eigen::Matrix3d::Identity();
  Vec3 mesh_centroid = Vec3::Zero();  // [m], mesh frame
  double union_volume_m3 = 0.0;       // estimated on the sample grid
  double volume_error = 0.0;
  double hausdorff_error = 0.0;
  double tolerance = 0.0;
  double equivalent_diameter_m = 0.0;  // of the sphere with the grain's volume
  std::vector<ClumpStep> history;      // one entry per sphere added
};

}  // namespace geometry
