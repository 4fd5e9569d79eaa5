#pragma once
// Exact reference queries on a triangle mesh with Embree: closest-point distance and
// inside/outside. The ground truth SDFs and wall contacts are measured against.
#include <memory>

#include "geometry/trimesh.hpp"

namespace mesh {

class ExactSurface {
 public:
  explicit ExactSurface(const geometry::TriMesh& mesh);
  ~ExactSurface();
  ExactSurface(const ExactSurface&) = delete;
  ExactSurface& operator=(const ExactSurface&) = delete;

  geometry::Vec3 closest_point(const geometry::Vec3& p) const;
  double distance(const geometry::Vec3& p) const;  // unsigned [m]
  // Inside the solid the mesh bounds: ray-crossing parity (majority of three rays in skew
  // directions), complemented for an inside-out mesh (negative signed volume: a container).
  // Meaningful for closed meshes.
  bool inside(const geometry::Vec3& p) const;
  // Inside by the majority of `rays` rays in random directions (fixed seed), each counting the
  // faces it leaves through minus those it enters through: the winding number along the ray.
  // For a file that is no closed surface (overlapping shells count once where parity would
  // cancel them; a ray through a hole is outvoted): the independent check of the winding-number
  // solid repair takes from such a file.
  bool inside_by_ray_majority(const geometry::Vec3& p, int rays) const;
  double signed_distance(const geometry::Vec3& p) const { return inside(p) ? -distance(p) : distance(p); }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mesh
