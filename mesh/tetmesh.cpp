// CGAL Mesh_3 on a polyhedral domain with protected features (the sharp edges of the surface
// are sampled by protecting balls first, so that the mesh's edges follow them).
#include "mesh/tetmesh.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polyhedral_mesh_domain_with_features_3.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/make_mesh_3.h>

#include <map>

#include <fmt/core.h>

#include "core/child_process.hpp"
#include "core/error.hpp"
#include "mesh/repair.hpp"
#include "mesh/weld.hpp"

namespace mesh {

namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
using Domain = CGAL::Polyhedral_mesh_domain_with_features_3<K, SurfaceMesh>;
// Sequential: the parallel mesher's result depends on the thread schedule.
using Tr = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Tr, Domain::Corner_index, Domain::Curve_index>;
using Criteria = CGAL::Mesh_criteria_3<Tr>;

SurfaceMesh surface_mesh(const TriMesh& m) {
  std::vector<Point> points;
  points.reserve(m.vertices.size());
  for (const Vec3& v : m.vertices) points.emplace_back(v.x(), v.y(), v.z());
  std::vector<std::array<std::size_t, 3>> faces;
  faces.reserve(m.triangles.size());
  for (const Triangle& t : m.triangles) faces.push_back({std::size_t(t[0]), std::size_t(t[1]), std::size_t(t[2])});
  SurfaceMesh sm;
  CGAL::Polygon_mesh_processing::polygon_soup_to_polygon_mesh(points, faces, sm);
  return sm;
}
// A cell whose four vertices lie in one plane (to rounding; exactly, they need not) with two or
// more faces on the boundary: a sliver Mesh_3 can leave lying on a flat part of the surface (on the gear die's wall, between
// protected edges), which exudation cannot remove and CalculiX refuses ("nonpositive jacobian").
// Dropped, it changes nothing: its other faces lie in the boundary's plane and become boundary.
template <class Cell>
bool is_flat_boundary_cell(const C3t3& c3t3, const Cell& c) {
  const Tr& tr = c3t3.triangulation();
  std::array<Vec3, 4> p;
  double longest = 0;
  for (int k = 0; k < 4; ++k) {
    const Point q = tr.geom_traits().construct_point_3_object()(tr.point(c, k));
    p[std::size_t(k)] = Vec3(q.x(), q.y(), q.z());
  }
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b) longest = std::max(longest, (p[a] - p[b]).norm());
  // Rounding of the coordinates: 1e-12 of the longest edge's cube (the gear's: 1e-19).
  if (std::abs(tet_volume(p[0], p[1], p[2], p[3])) > 1e-12 * longest * longest * longest) return false;
  int boundary_faces = 0;
  for (int k = 0; k < 4; ++k) boundary_faces += c3t3.is_in_complex(c->neighbor(k)) ? 0 : 1;
  return boundary_faces >= 2;
}

// Vertices closer than the facet distance welded, when the body stays one closed, oriented
// surface without degenerate faces or crossings (repair's checks). An edge that short between
// sharp features (the planetary gear set's ring gear has edges of 2 µm) makes Mesh_3 protect
// them with balls that small and refine all around them: alone, the ring gear's mesh had not
// ended after 2 minutes, a planet's took under 30 s. The mesh's boundary may lie the facet
// distance from the surface anyway.
TriMesh without_edges_shorter_than(const TriMesh& body, double length) {
  const WeldedMesh welded = weld_close_vertices(body, length);
  if (welded.merged == 0) return body;
  std::vector<TriMesh> parts = separate_bodies(welded.mesh);  // also drops the welded vertices
  if (parts.size() != 1) return body;
  const MeshReport welded_report = inspect(parts.front());
  if (!welded_report.closed || welded_report.inconsistent_edges > 0 || welded_report.degenerate_faces > 0 ||
      welded_report.self_intersections > 0)
    return body;
  return std::move(parts.front());
}

TetMesh tetrahedralise_body(const TriMesh& body, const TetMeshOptions& o) {
  SurfaceMesh sm = surface_mesh(without_edges_shorter_than(body, o.facet_distance_m));
  CGAL::Random seeded(0);  // the domain's own sampling; make_mesh_3 reseeds CGAL's default generator
  Domain domain(sm, &seeded);
  domain.detect_features(o.feature_angle_deg);
  namespace params = CGAL::parameters;
  // Radius-edge ratio 2 and facet angle 25° are CGAL's documented bounds for which refinement
  // terminates; perturbation and exudation then remove slivers (without a time limit, which
  // would make the result depend on the machine's speed).
  const Criteria criteria(params::edge_size = o.element_size_m, params::facet_angle = 25,
                          params::facet_size = o.element_size_m, params::facet_distance = o.facet_distance_m,
                          params::cell_radius_edge_ratio = 2, params::cell_size = o.element_size_m);
  C3t3 c3t3 = CGAL::make_mesh_3<C3t3>(domain, criteria, params::perturb(params::time_limit = 0),
                                      params::exude(params::time_limit = 0));

  TetMesh out;
  std::map<Tr::Vertex_handle, int> index;
  const Tr& tr = c3t3.triangulation();
  auto node = [&](Tr::Vertex_handle v) {
    auto [it, added] = index.emplace(v, int(out.nodes.size()));
    if (added) {
      const Point p = tr.geom_traits().construct_point_3_object()(tr.point(v));
      out.nodes.emplace_back(p.x(), p.y(), p.z());
    }
    return it->second;
  };
  for (auto c = c3t3.cells_in_complex_begin(); c != c3t3.cells_in_complex_end(); ++c) {
    if (is_flat_boundary_cell(c3t3, c)) {
      ++out.dropped_boundary_slivers;
      continue;
    }
    Tet t{node(c->vertex(0)), node(c->vertex(1)), node(c->vertex(2)), node(c->vertex(3))};
    if (tet_volume(out.nodes[t[0]], out.nodes[t[1]], out.nodes[t[2]], out.nodes[t[3]]) < 0) std::swap(t[2], t[3]);
    out.tets.push_back(t);
  }
  for (auto e = c3t3.edges_in_complex_begin(); e != c3t3.edges_in_complex_end(); ++e)
    out.feature_edges.push_back({node(e->first->vertex(e->second)), node(e->first->vertex(e->third))});
  return out;
}

// Each separate body alone, their meshes joined: Mesh_3 keeps the protecting balls of sharp
// edges apart, so edges of two bodies 0.11 mm apart (the teeth of the planetary gear set's
// gears, where they mesh) shrank the balls and the elements around them to that gap, and the
// gear set's mesh had not ended after 8 minutes (README, "Shared dies through the pipeline").
TetMesh tetrahedralise_here(const TriMesh& surface, const TetMeshOptions& o) {
  const std::vector<TriMesh> bodies = separate_bodies(surface);
  if (bodies.size() == 1) return tetrahedralise_body(surface, o);  // as given, vertex order and all
  TetMesh out;
  for (const TriMesh& body : bodies) {
    const TetMesh part = tetrahedralise_body(body, o);
    const int offset = int(out.nodes.size());
    out.nodes.insert(out.nodes.end(), part.nodes.begin(), part.nodes.end());
    for (Tet t : part.tets) {
      for (int& n : t) n += offset;
      out.tets.push_back(t);
    }
    for (std::array<int, 2> e : part.feature_edges) out.feature_edges.push_back({e[0] + offset, e[1] + offset});
    out.dropped_boundary_slivers += part.dropped_boundary_slivers;
  }
  return out;
}

}  // namespace

// In a child process (core/child_process.hpp): a large part can take Mesh_3 many minutes, and
// the user must hear from it and be able to stop it without losing the fill.
TetMesh tetrahedralise(const TriMesh& surface, const TetMeshOptions& o, const std::string& source,
                       const diefill::ChildWait& wait) {
  if (!(o.element_size_m > 0) || !(o.facet_distance_m > 0))
    throw diefill::InputError(source, "fem.element_size", "element size and facet distance must be positive",
                              "Give a positive element size");
  const diefill::ChildResult child = diefill::run_in_child(
      [&] {
        const TetMesh m = tetrahedralise_here(surface, o);
        return diefill::ByteWriter().put(m.nodes).put(m.tets).put(m.feature_edges).put(m.dropped_boundary_slivers).take();
      },
      wait);
  if (child.outcome == diefill::ChildOutcome::stopped) throw TetMeshingStopped();
  TetMesh out;
  diefill::ByteReader in(child.bytes);
  in.get(out.nodes);
  in.get(out.tets);
  in.get(out.feature_edges);
  in.get(out.dropped_boundary_slivers);
  if (child.outcome != diefill::ChildOutcome::done || !in.ok())
    throw diefill::InputError(source, "surface", fmt::format("CGAL's tetrahedral mesher failed on it (status {})", child.status),
                              "Check that the die is a closed solid; or set fem.elements = \"none\"");
  if (out.tets.empty())
    throw diefill::InputError(source, "surface", "CGAL's mesher made no tetrahedron inside it",
                              "Check that the die is a closed solid larger than the element size");
  return out;
}

}  // namespace mesh
