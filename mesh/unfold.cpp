// Removal of a shell's self-intersections (CGAL PMP, experimental in CGAL 5.5), in its own
// translation unit: its header is as heavy to compile as corefinement.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_self_intersections.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include "mesh/cgal_ops.hpp"

namespace mesh::detail {

bool remove_folds(geometry::TriMesh& shell) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Point = K::Point_3;
  namespace PMP = CGAL::Polygon_mesh_processing;
  std::vector<Point> points;
  for (const geometry::Vec3& v : shell.vertices) points.emplace_back(v.x(), v.y(), v.z());
  std::vector<std::array<std::size_t, 3>> faces;
  for (const geometry::Triangle& t : shell.triangles) faces.push_back({std::size_t(t[0]), std::size_t(t[1]), std::size_t(t[2])});
  if (!PMP::is_polygon_soup_a_polygon_mesh(faces)) return false;
  CGAL::Surface_mesh<Point> sm;
  PMP::polygon_soup_to_polygon_mesh(points, faces, sm);
  // Without preserving the genus a fold may part into separate shells, which the union takes.
  if (!PMP::experimental::remove_self_intersections(sm, CGAL::parameters::preserve_genus(false)) ||
      PMP::does_self_intersect(sm) || !CGAL::is_closed(sm))
    return false;
  sm.collect_garbage();
  shell = geometry::TriMesh{};
  for (auto v : sm.vertices()) {
    const Point& p = sm.point(v);
    shell.vertices.emplace_back(p.x(), p.y(), p.z());
  }
  for (auto f : sm.faces()) {
    geometry::Triangle t{};
    int k = 0;
    for (auto v : CGAL::vertices_around_face(sm.halfedge(f), sm)) t[k++] = int(v.idx());
    shell.triangles.push_back(t);
  }
  return true;
}

}  // namespace mesh::detail
