#pragma once
// Exact reference queries on a triangle mesh with Embree: closest-point distance and
// inside/outside. The ground truth SDFs and wall contacts are measured against.
#include <memory>

#include "mesh/trimesh.hpp"

namespace mesh {

class ExactSurface {
 public:
  explicit ExactSurface(const TriMesh& mesh);
  ~ExactSurface();
  ExactSurface(const ExactSurface&) = delete;
  ExactSurface& operator=(const ExactSurface&) = delete;

  Vec3 closest_point(const Vec3& p) const;
  double distance(const Vec3& p) const;  // unsigned [m]
  // Inside the solid the mesh bounds: ray-crossing parity (majority of three rays in skew
  // directions), complemented for an inside-out mesh (negative signed volume: a container).
  // Meaningful for closed meshes.
  bool inside(const Vec3& p) const;
  double signed_distance(const Vec3& p) const { return inside(p) ? -distance(p) : distance(p); }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mesh
