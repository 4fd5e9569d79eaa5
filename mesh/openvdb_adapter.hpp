#pragma once
// Internal to the mesh module, for its OpenVDB translation units only (the headers are heavy).
#include <openvdb/openvdb.h>

#include <mutex>

#include "geometry/trimesh.hpp"

namespace mesh::detail {

inline void initialise_openvdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

// Points go to OpenVDB's index space in double precision, without a float copy.
struct TriMeshAdapter {
  const geometry::TriMesh& mesh;
  double inverse_voxel;
  geometry::Vec3 origin = geometry::Vec3::Zero();  // the world point of index (0, 0, 0) [m]
  std::size_t polygonCount() const { return mesh.triangles.size(); }
  std::size_t pointCount() const { return mesh.vertices.size(); }
  std::size_t vertexCount(std::size_t) const { return 3; }
  void getIndexSpacePoint(std::size_t n, std::size_t v, openvdb::Vec3d& pos) const {
    const geometry::Vec3& p = mesh.vertices[std::size_t(mesh.triangles[n][v])];
    const geometry::Vec3 q = p - origin;
    pos = openvdb::Vec3d(q.x(), q.y(), q.z()) * inverse_voxel;
  }
};

}  // namespace mesh::detail
