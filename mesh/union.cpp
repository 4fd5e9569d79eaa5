// Exact union of intersecting closed shells by corefinement (CGAL PMP), in its own translation
// unit: corefinement is the heaviest CGAL header the project uses.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include "core/log.hpp"
#include "mesh/cgal_ops.hpp"

namespace mesh::detail {

namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;
}  // namespace

bool union_of_shells(const TriMesh& closed_shells, TriMesh& out) {
  std::vector<Point> points;
  for (const Vec3& v : closed_shells.vertices) points.emplace_back(v.x(), v.y(), v.z());
  std::vector<std::array<std::size_t, 3>> faces;
  for (const Triangle& t : closed_shells.triangles)
    faces.push_back({std::size_t(t[0]), std::size_t(t[1]), std::size_t(t[2])});
  SurfaceMesh all;
  if (!PMP::is_polygon_soup_a_polygon_mesh(faces)) {
    diefill::log::debug("union: the surface is not a polygon mesh");
    return false;
  }
  PMP::polygon_soup_to_polygon_mesh(points, faces, all);
  std::vector<SurfaceMesh> shells;
  PMP::split_connected_components(all, shells);
  for (SurfaceMesh& s : shells) {
    if (!CGAL::is_closed(s) || PMP::does_self_intersect(s)) {
      diefill::log::debug("union: a shell of {} faces is {}", s.number_of_faces(),
                          CGAL::is_closed(s) ? "self-intersecting" : "open");
      return false;
    }
    if (!PMP::is_outward_oriented(s)) PMP::reverse_face_orientations(s);
  }
  // Fold the shells into one; shells that do not touch the result are kept as they are by the
  // union as well (a union of disjoint solids is their juxtaposition).
  SurfaceMesh result = shells.front();
  for (std::size_t i = 1; i < shells.size(); ++i) {
    SurfaceMesh next;
    if (!PMP::corefine_and_compute_union(result, shells[i], next)) {
      diefill::log::debug("union: corefinement failed at shell {} of {}", i, shells.size());
      return false;
    }
    result = std::move(next);
  }
  out = TriMesh{};
  std::vector<int> index(result.number_of_vertices() + result.number_of_removed_vertices(), -1);
  for (auto v : result.vertices()) {
    index[v.idx()] = int(out.vertices.size());
    const Point& p = result.point(v);
    out.vertices.emplace_back(p.x(), p.y(), p.z());
  }
  for (auto f : result.faces()) {
    Triangle t{};
    int k = 0;
    for (auto v : CGAL::vertices_around_face(result.halfedge(f), result)) t[k++] = index[v.idx()];
    out.triangles.push_back(t);
  }
  return true;
}

}  // namespace mesh::detail
