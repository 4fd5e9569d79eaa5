// CGAL Mesh_3 on a polyhedral domain with protected features (the sharp edges of the surface
// are sampled by protecting balls first, so that the mesh's edges follow them).
#include "mesh/tetmesh.hpp"

#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Polygon_mesh_processing/repair_degeneracies.h>
#include <CGAL/Polyhedral_mesh_domain_with_features_3.h>
#include <CGAL/make_mesh_3.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <stdexcept>

#include <fmt/core.h>

#include "core/child_process.hpp"
#include "core/error.hpp"
#include "mesh/cgal_ops.hpp"
#include "mesh/cgal_surface_mesh.hpp"
#include "mesh/repair.hpp"
#include "mesh/weld.hpp"

namespace mesh {

namespace {
using K = detail::CgalKernel;
using Point = detail::CgalPoint;
using detail::SurfaceMesh;
using Domain = CGAL::Polyhedral_mesh_domain_with_features_3<K, SurfaceMesh>;
// Sequential: the parallel mesher's result depends on the thread schedule.
using Tr = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Tr, Domain::Corner_index, Domain::Curve_index>;
using Criteria = CGAL::Mesh_criteria_3<Tr>;

// A cell whose four vertices lie in one plane (to rounding; exactly, they need not) with two or
// more faces on the boundary: a sliver Mesh_3 can leave lying on a flat part of the surface (on the gear die's wall, between
// protected edges), which exudation cannot remove and CalculiX refuses ("nonpositive jacobian").
// Dropped, it changes nothing: its other faces lie in the boundary's plane and become boundary.
template <class Cell>
bool is_flat_boundary_cell(const C3t3& c3t3, const Cell& c) {
  const Tr& tr = c3t3.triangulation();
  std::array<geometry::Vec3, 4> p;
  double longest = 0;
  for (int k = 0; k < 4; ++k) {
    const Point q = tr.geom_traits().construct_point_3_object()(tr.point(c, k));
    p[std::size_t(k)] = geometry::Vec3(q.x(), q.y(), q.z());
  }
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b) longest = std::max(longest, (p[a] - p[b]).norm());
  // Rounding of the coordinates: 1e-12 of the longest edge's cube (the gear's: 1e-19).
  if (std::abs(geometry::tet_volume(p[0], p[1], p[2], p[3])) > 1e-12 * longest * longest * longest) return false;
  int boundary_faces = 0;
  for (int k = 0; k < 4; ++k) boundary_faces += c3t3.is_in_complex(c->neighbor(k)) ? 0 : 1;
  return boundary_faces >= 2;
}

// One closed, oriented surface without degenerate faces or crossings (repair's checks), or none.
std::optional<geometry::TriMesh> clean_single_body(const geometry::TriMesh& mesh) {
  std::vector<geometry::TriMesh> parts = geometry::separate_bodies(mesh);  // also drops unused vertices
  if (parts.size() != 1) return std::nullopt;
  const MeshReport report = inspect(parts.front());
  if (!report.closed || report.inconsistent_edges > 0 || report.degenerate_faces > 0 || report.self_intersections > 0)
    return std::nullopt;
  return std::move(parts.front());
}

// Edges shorter than `length` collapsed, one at a time where the surface's topology allows
// (CGAL's remove_almost_degenerate_faces: a needle threshold of 1 makes every face's shortest
// edge a candidate, the length bounds which go; the endpoint kept is the one that changes the
// volume least), and caps no taller than `length` flipped: each vertex moves at most `length`
// and none is made. Where two sheets of the surface pass closer than `length` (on the turbine
// blade, at two faces of its cut), a collapse can fold one through the other: the vertices
// around each crossing face (its box grown by `length`) are then kept as they are and the
// collapse is done again from the start, a few times at most.
std::optional<geometry::TriMesh> with_short_edges_collapsed(const geometry::TriMesh& body, double length) {
  constexpr int attempts = 4;
  std::vector<geometry::Box> keep_within;
  for (int attempt = 0; attempt < attempts; ++attempt) {
    SurfaceMesh sm;
    if (!detail::to_surface_mesh(body, sm)) return std::nullopt;
    auto is_kept = sm.add_property_map<SurfaceMesh::Vertex_index, bool>("v:kept", false).first;
    for (const SurfaceMesh::Vertex_index v : sm.vertices()) {
      const geometry::Vec3 p(sm.point(v).x(), sm.point(v).y(), sm.point(v).z());
      is_kept[v] = std::any_of(keep_within.begin(), keep_within.end(), [&](const geometry::Box& b) {
        return (p.array() >= b.lo.array()).all() && (p.array() <= b.hi.array()).all();
      });
    }
    const double cap_cosine = std::cos(160 * std::numbers::pi / 180);  // CGAL's example: an angle over 160°
    CGAL::Polygon_mesh_processing::experimental::remove_almost_degenerate_faces(
        sm, cap_cosine, 1.0, length,
        CGAL::parameters::flip_triangle_height_threshold(length).vertex_is_constrained_map(is_kept));
    geometry::TriMesh collapsed = detail::to_trimesh(sm);
    const std::vector<bool> faulty = detail::faulty_triangles(collapsed);
    if (std::find(faulty.begin(), faulty.end(), true) == faulty.end()) return clean_single_body(collapsed);
    for (std::size_t f = 0; f < faulty.size(); ++f) {
      if (!faulty[f]) continue;
      geometry::Box b;
      for (const int v : collapsed.triangles[f]) b.extend(collapsed.vertices[std::size_t(v)]);
      keep_within.push_back({b.lo - geometry::Vec3::Constant(length), b.hi + geometry::Vec3::Constant(length)});
    }
  }
  return std::nullopt;
}

// Edges shorter than the facet distance removed before meshing: an edge that short between sharp
// features makes Mesh_3 protect them with balls that small and refine all around them (the
// planetary gear set's ring gear has edges of 2 µm: alone, its mesh had not ended after 2
// minutes, a planet's took under 30 s), and leaves elements CalculiX refuses (the turbine
// blade's edges of 0.2-0.5 µm, docs/MESHES.md, "Shared dies through the pipeline"). First the vertices
// that close welded, which also closes a seam folding through itself in slivers that thin, where
// that leaves a clean body (on the blade it crosses the surface); then, on that or the body as
// it is, the short edges collapsed and the flat caps flipped along the surface (the flanged
// ring's re-mesh has caps 0.1 µm high, which welding leaves). The mesh's boundary may lie the
// facet distance from the surface anyway.
geometry::TriMesh without_edges_shorter_than(const geometry::TriMesh& body, double length) {
  std::optional<geometry::TriMesh> welded;
  if (const WeldedMesh w = weld_close_vertices(body, length); w.merged > 0) welded = clean_single_body(w.mesh);
  const geometry::TriMesh& base = welded ? *welded : body;
  if (std::optional<geometry::TriMesh> clean = with_short_edges_collapsed(base, length)) return std::move(*clean);
  return base;
}

geometry::TetMesh tetrahedralise_body(const geometry::TriMesh& body, const TetMeshOptions& o) {
  SurfaceMesh sm;
  // In the child process (tetrahedralise): its failure is reported with the remedy there.
  if (!detail::to_surface_mesh(without_edges_shorter_than(body, o.facet_distance_m), sm))
    throw std::invalid_argument("the surface is not a polygon mesh");
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

  geometry::TetMesh out;
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
    // CGAL's cells are positively oriented, which is C3D4's order: kept as they come, so that a
    // cell the coordinates' rounding turned inside out is counted (tet_quality), not hidden.
    out.tets.push_back({node(c->vertex(0)), node(c->vertex(1)), node(c->vertex(2)), node(c->vertex(3))});
  }
  for (auto e = c3t3.edges_in_complex_begin(); e != c3t3.edges_in_complex_end(); ++e)
    out.feature_edges.push_back({node(e->first->vertex(e->second)), node(e->first->vertex(e->third))});
  return out;
}

// Each separate body alone, their meshes joined: Mesh_3 keeps the protecting balls of sharp
// edges apart, so edges of two bodies 0.11 mm apart (the teeth of the planetary gear set's
// gears, where they mesh) shrank the balls and the elements around them to that gap, and the
// gear set's mesh had not ended after 8 minutes (docs/MESHES.md, "Shared dies through the pipeline").
geometry::TetMesh tetrahedralise_here(const geometry::TriMesh& surface, const TetMeshOptions& o) {
  const std::vector<geometry::TriMesh> bodies = geometry::separate_bodies(surface);
  if (bodies.size() == 1) return tetrahedralise_body(surface, o);  // as given, vertex order and all
  geometry::TetMesh out;
  for (const geometry::TriMesh& body : bodies) {
    const geometry::TetMesh part = tetrahedralise_body(body, o);
    const int offset = int(out.nodes.size());
    out.nodes.insert(out.nodes.end(), part.nodes.begin(), part.nodes.end());
    for (geometry::Tet t : part.tets) {
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
geometry::TetMesh tetrahedralise(const geometry::TriMesh& surface, const TetMeshOptions& o, const std::string& source,
                                 const diefill::ChildWait& wait) {
  if (!(o.element_size_m > 0) || !(o.facet_distance_m > 0))
    throw diefill::InputError(source, "fem.element_size", "element size and facet distance must be positive",
                              "Give a positive element size");
  const diefill::ChildResult child = diefill::run_in_child(
      [&] {
        const geometry::TetMesh m = tetrahedralise_here(surface, o);
        return diefill::ByteWriter().put(m.nodes).put(m.tets).put(m.feature_edges).put(m.dropped_boundary_slivers).take();
      },
      wait);
  if (child.outcome == diefill::ChildOutcome::stopped) throw TetMeshingStopped();
  geometry::TetMesh out;
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
