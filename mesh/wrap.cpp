// Alpha wrapping and surface distances: the CGAL AABB-tree side of the mesh module.
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/alpha_wrap_3.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <vector>

#include "mesh/cgal_ops.hpp"
#include "mesh/cgal_surface_mesh.hpp"

namespace mesh::detail {

namespace {
using K = CgalKernel;
using Point = CgalPoint;
using Triangle3 = K::Triangle_3;
using TriangleIt = std::vector<Triangle3>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<K, TriangleIt>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

Point to_point(const geometry::Vec3& v) { return {v.x(), v.y(), v.z()}; }

std::vector<Triangle3> triangles_of(const geometry::TriMesh& mesh) {
  std::vector<Triangle3> out;
  out.reserve(mesh.triangles.size());
  for (const geometry::Triangle& t : mesh.triangles)
    out.emplace_back(to_point(mesh.vertices[t[0]]), to_point(mesh.vertices[t[1]]),
                     to_point(mesh.vertices[t[2]]));
  return out;
}

// Largest distance from a barycentric grid of sample points on `from` (about 16 along a
// triangle's longest edge at most) to `tree`, over the points `counts` accepts, where, and the
// accepted points beyond `collect_beyond_m`, for the triangles [first, last). `counts` is asked
// only of points that would change the answer: on buried faces it would cost two winding numbers
// a point.
FarthestSample farthest_in(const geometry::TriMesh& from, const Tree& tree, const SampleFilter& counts, double collect_beyond_m,
                           double diagonal, std::size_t first, std::size_t last) {
  FarthestSample out;
  const double collect_squared = collect_beyond_m * collect_beyond_m;
  double worst_squared = 0.0;
  for (std::size_t n = first; n < last; ++n) {
    const geometry::Triangle& t = from.triangles[n];
    const geometry::Vec3& a = from.vertices[t[0]];
    const geometry::Vec3& b = from.vertices[t[1]];
    const geometry::Vec3& c = from.vertices[t[2]];
    const geometry::Vec3 normal = (b - a).cross(c - a).normalized();
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const int k = std::clamp(int(std::ceil(longest / (diagonal * 1e-3))), 1, 16);
    for (int i = 0; i <= k; ++i)
      for (int j = 0; i + j <= k; ++j) {
        const geometry::Vec3 v = a + (b - a) * (double(i) / k) + (c - a) * (double(j) / k);
        const double d2 = tree.squared_distance(to_point(v));
        if (d2 <= worst_squared && d2 <= collect_squared) continue;
        if (counts && !counts(v, normal)) continue;
        if (d2 > collect_squared) out.beyond.push_back(v);
        if (d2 > worst_squared) {
          worst_squared = d2;
          out.point = v;
          out.normal = normal;
        }
      }
  }
  out.distance_m = std::sqrt(worst_squared);
  return out;
}

// The same over all of `from`, on every core: fixed runs of triangles, each with its own running
// maximum, merged in order, so that the farthest point (the first at the largest distance) and
// the points beyond are the serial walk's, and `counts` is asked of the same points on any
// thread count (a few more than one running maximum would ask: it must be safe to call
// concurrently). The sampling took half of a re-mesh's time on one core (the planetary gear set).
FarthestSample farthest_from(const geometry::TriMesh& from, const Tree& tree, const SampleFilter& counts,
                             double collect_beyond_m = std::numeric_limits<double>::infinity()) {
  constexpr std::size_t run = 1024;  // [triangles]
  const std::size_t runs = (from.triangles.size() + run - 1) / run;
  const double diagonal = geometry::bounding_box(from).size().norm();
  // The tree's distance structure is built on its first query: here, before the threads share it.
  tree.squared_distance(to_point(from.vertices[std::size_t(from.triangles.front()[0])]));
  std::vector<FarthestSample> parts(runs);
  tbb::parallel_for(std::size_t(0), runs, [&](std::size_t r) {
    parts[r] = farthest_in(from, tree, counts, collect_beyond_m, diagonal, r * run,
                           std::min(from.triangles.size(), (r + 1) * run));
  });
  FarthestSample out;
  for (FarthestSample& part : parts) {
    if (part.distance_m > out.distance_m) out.distance_m = part.distance_m, out.point = part.point, out.normal = part.normal;
    out.beyond.insert(out.beyond.end(), part.beyond.begin(), part.beyond.end());
  }
  return out;
}
}  // namespace

geometry::TriMesh alpha_wrap(const geometry::TriMesh& soup, double alpha, double offset) {
  std::vector<Point> points;
  points.reserve(soup.vertices.size());
  for (const geometry::Vec3& v : soup.vertices) points.push_back(to_point(v));
  std::vector<std::array<std::size_t, 3>> faces;
  faces.reserve(soup.triangles.size());
  for (const geometry::Triangle& t : soup.triangles)
    faces.push_back({std::size_t(t[0]), std::size_t(t[1]), std::size_t(t[2])});

  SurfaceMesh wrap;
  CGAL::alpha_wrap_3(points, faces, alpha, offset, wrap);
  return to_trimesh(wrap);
}

FarthestSample farthest_sample(const geometry::TriMesh& from, const geometry::TriMesh& to, const SampleFilter& counts,
                               double collect_beyond_m) {
  const std::vector<Triangle3> target = triangles_of(to);
  if (target.empty() || from.triangles.empty()) return {};
  Tree tree(target.begin(), target.end());
  tree.accelerate_distance_queries();
  return farthest_from(from, tree, counts, collect_beyond_m);
}

double max_distance(const geometry::TriMesh& from, const geometry::TriMesh& to, const SampleFilter& counts) {
  return farthest_sample(from, to, counts).distance_m;
}

double max_distance(const geometry::TriMesh& from, const geometry::TriMesh& to, Samples samples) {
  const std::vector<Triangle3> target = triangles_of(to);
  if (target.empty() || from.triangles.empty()) return 0.0;
  Tree tree(target.begin(), target.end());
  tree.accelerate_distance_queries();
  if (samples == Samples::all) return farthest_from(from, tree, SampleFilter{}).distance_m;
  // Ray-crossing parity, the majority of three skew rays (one may graze an edge).
  auto outside_target = [&](const geometry::Vec3& v, const geometry::Vec3&) {
    int votes = 0;
    for (const K::Vector_3 direction : {K::Vector_3(0.5773, 0.5774, 0.5775), K::Vector_3(-0.6123, 0.3211, 0.7222),
                                        K::Vector_3(0.2345, -0.8765, -0.4203)})
      votes += tree.number_of_intersected_primitives(K::Ray_3(to_point(v), direction)) % 2;
    return votes < 2;
  };
  return farthest_from(from, tree, outside_target).distance_m;
}

}  // namespace mesh::detail
