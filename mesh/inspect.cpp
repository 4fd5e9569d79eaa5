// Mesh checks (CGAL predicates): what `diefill sdf` reports before and after repair, and the
// crossing-pair test repair and the re-meshes use.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/box_intersection_d.h>

#include <algorithm>
#include <map>
#include <numeric>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "mesh/cgal_ops.hpp"
#include "mesh/repair.hpp"

namespace mesh {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;

Point to_point(const geometry::Vec3& v) { return {v.x(), v.y(), v.z()}; }

bool is_degenerate(const geometry::TriMesh& mesh, const geometry::Triangle& t) {
  if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) return true;
  return CGAL::collinear(to_point(mesh.vertices[t[0]]), to_point(mesh.vertices[t[1]]),
                         to_point(mesh.vertices[t[2]]));
}

// Union-find over triangle indices, for shells.
struct DisjointSets {
  std::vector<std::size_t> parent;
  explicit DisjointSets(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  std::size_t find(std::size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void unite(std::size_t a, std::size_t b) { parent[find(a)] = find(b); }
};

// Edge incidence of an indexed mesh: boundary, non-manifold and inconsistently oriented edges,
// and shells (components connected through shared edges).
void count_edges_and_shells(const geometry::TriMesh& mesh, MeshReport& report) {
  struct Incidence {
    int faces = 0;
    int forward = 0;  // triangles running the edge from the smaller to the larger index
    std::size_t first_face = 0;
  };
  std::unordered_map<std::uint64_t, Incidence> edges;
  edges.reserve(mesh.triangles.size() * 2);
  DisjointSets sets(mesh.triangles.size());
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    const geometry::Triangle& t = mesh.triangles[f];
    for (int k = 0; k < 3; ++k) {
      std::uint32_t a = std::uint32_t(t[k]), b = std::uint32_t(t[(k + 1) % 3]);
      if (a == b) continue;
      const bool forward = a < b;
      if (!forward) std::swap(a, b);
      Incidence& e = edges[(std::uint64_t(a) << 32) | b];
      if (e.faces == 0) e.first_face = f;
      else sets.unite(f, e.first_face);
      ++e.faces;
      e.forward += forward ? 1 : 0;
    }
  }
  for (const auto& [key, e] : edges) {
    if (e.faces == 1) ++report.boundary_edges;
    else if (e.faces > 2) ++report.non_manifold_edges;
    else if (e.forward != 1) ++report.inconsistent_edges;
  }
  std::vector<char> is_root(mesh.triangles.size(), 0);
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) is_root[sets.find(f)] = 1;
  report.shells = std::size_t(std::count(is_root.begin(), is_root.end(), 1));
}

std::size_t count_duplicate_faces(const geometry::TriMesh& mesh) {
  std::map<std::array<int, 3>, int> seen;
  std::size_t duplicates = 0;
  for (geometry::Triangle t : mesh.triangles) {
    std::sort(t.begin(), t.end());
    if (seen[t]++ > 0) ++duplicates;
  }
  return duplicates;
}

}  // namespace

namespace detail {

namespace {

// Whether two triangles whose boxes overlap cross: sharing an edge is a neighbour, touching at
// one vertex is fine, crossing elsewhere is not (each one's edge opposite the shared vertex is
// tested against the other triangle).
bool triangles_cross(const geometry::TriMesh& mesh, std::size_t fa, std::size_t fb) {
  const geometry::Triangle& a = mesh.triangles[fa];
  const geometry::Triangle& b = mesh.triangles[fb];
  int shared = 0, sa = -1, sb = -1;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (a[i] == b[j]) ++shared, sa = i, sb = j;
  auto P = [&](int v) { return to_point(mesh.vertices[std::size_t(v)]); };
  const K::Triangle_3 ta(P(a[0]), P(a[1]), P(a[2])), tb(P(b[0]), P(b[1]), P(b[2]));
  if (shared == 0) return CGAL::do_intersect(ta, tb);
  if (shared != 1) return false;
  const K::Segment_3 ea(P(a[(sa + 1) % 3]), P(a[(sa + 2) % 3]));
  const K::Segment_3 eb(P(b[(sb + 1) % 3]), P(b[(sb + 2) % 3]));
  return CGAL::do_intersect(ea, tb) || CGAL::do_intersect(eb, ta);
}

// The boxes' overlaps are found in one pass and their exact tests run on every core a batch at a
// time: on a million triangles this check took 12.6 of the inspection's 13.0 s on one core, and
// the inspection takes 7.3 s with the tests on two. Calls `crossing(fa, fb)` for each crossing
// pair, one batch's pairs after another, on the calling thread.
template <class OnCrossing>
void for_each_crossing_pair(const geometry::TriMesh& mesh, OnCrossing crossing) {
  using BoxHandle = CGAL::Box_intersection_d::Box_with_handle_d<double, 3, std::size_t,
                                                                CGAL::Box_intersection_d::ID_EXPLICIT>;
  std::vector<BoxHandle> boxes;
  boxes.reserve(mesh.triangles.size());
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    if (is_degenerate(mesh, mesh.triangles[f])) continue;  // reported as degenerate instead
    const geometry::Triangle& t = mesh.triangles[f];
    CGAL::Bbox_3 b = to_point(mesh.vertices[t[0]]).bbox() + to_point(mesh.vertices[t[1]]).bbox() +
                     to_point(mesh.vertices[t[2]]).bbox();
    boxes.emplace_back(b, f);
  }
  constexpr std::size_t batch = std::size_t(1) << 16;
  std::vector<std::pair<std::size_t, std::size_t>> overlaps;
  std::vector<char> crosses;
  overlaps.reserve(batch);
  const auto test_batch = [&] {
    crosses.assign(overlaps.size(), 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, overlaps.size()), [&](const tbb::blocked_range<std::size_t>& range) {
      for (std::size_t k = range.begin(); k < range.end(); ++k)
        crosses[k] = triangles_cross(mesh, overlaps[k].first, overlaps[k].second);
    });
    for (std::size_t k = 0; k < overlaps.size(); ++k)
      if (crosses[k]) crossing(overlaps[k].first, overlaps[k].second);
    overlaps.clear();
  };
  CGAL::box_self_intersection_d(boxes.begin(), boxes.end(), [&](const BoxHandle& ba, const BoxHandle& bb) {
    overlaps.emplace_back(ba.handle(), bb.handle());
    if (overlaps.size() == batch) test_batch();
  });
  test_batch();
}

}  // namespace

std::size_t count_self_intersections(const geometry::TriMesh& mesh) {
  std::size_t pairs = 0;
  for_each_crossing_pair(mesh, [&](std::size_t, std::size_t) { ++pairs; });
  return pairs;
}

std::vector<bool> faulty_triangles(const geometry::TriMesh& mesh) {
  std::vector<bool> faulty(mesh.triangles.size(), false);
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) faulty[f] = is_degenerate(mesh, mesh.triangles[f]);
  for_each_crossing_pair(mesh, [&](std::size_t fa, std::size_t fb) { faulty[fa] = faulty[fb] = true; });
  return faulty;
}

}  // namespace detail

MeshReport inspect(const geometry::TriMesh& mesh) {
  MeshReport r;
  r.triangles = mesh.triangles.size();
  r.vertices = mesh.vertices.size();
  r.bbox = geometry::bounding_box(mesh);
  for (const geometry::Triangle& t : mesh.triangles) {
    if (is_degenerate(mesh, t)) ++r.degenerate_faces;
    r.area_m2 += 0.5 * (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                           .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]])
                           .norm();
  }
  r.duplicate_faces = count_duplicate_faces(mesh);
  count_edges_and_shells(mesh, r);
  r.self_intersections = detail::count_self_intersections(mesh);
  r.closed = r.triangles > 0 && r.boundary_edges == 0 && r.non_manifold_edges == 0;
  r.volume_m3 = geometry::signed_volume(mesh);
  if (!r.closed) r.orientation = "undefined (open)";
  else if (r.inconsistent_edges > 0) r.orientation = "inconsistent";
  else r.orientation = r.volume_m3 >= 0 ? "outward" : "inward";
  return r;
}

}  // namespace mesh
