#include "mesh/cgal_surface_mesh.hpp"

#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>

namespace mesh::detail {

geometry::TriMesh to_trimesh(const SurfaceMesh& sm) {
  geometry::TriMesh out;
  std::vector<int> index(sm.number_of_vertices() + sm.number_of_removed_vertices(), -1);
  for (auto v : sm.vertices()) {
    index[v.idx()] = int(out.vertices.size());
    const CgalPoint& p = sm.point(v);
    out.vertices.emplace_back(p.x(), p.y(), p.z());
  }
  for (auto f : sm.faces()) {
    geometry::Triangle t{};
    int k = 0;
    for (auto v : CGAL::vertices_around_face(sm.halfedge(f), sm)) {
      if (k < 3) t[std::size_t(k)] = index[v.idx()];
      ++k;
    }
    if (k == 3) out.triangles.push_back(t);
  }
  return out;
}

bool to_surface_mesh(const geometry::TriMesh& mesh, SurfaceMesh& out) {
  namespace PMP = CGAL::Polygon_mesh_processing;
  std::vector<CgalPoint> points;
  points.reserve(mesh.vertices.size());
  for (const geometry::Vec3& v : mesh.vertices) points.emplace_back(v.x(), v.y(), v.z());
  std::vector<std::array<std::size_t, 3>> faces;
  faces.reserve(mesh.triangles.size());
  for (const geometry::Triangle& t : mesh.triangles) faces.push_back({std::size_t(t[0]), std::size_t(t[1]), std::size_t(t[2])});
  if (!PMP::is_polygon_soup_a_polygon_mesh(faces)) return false;
  PMP::polygon_soup_to_polygon_mesh(points, faces, out);
  return true;
}

}  // namespace mesh::detail
