// Multi-sphere clump templates: exact mass properties, then a greedy choice of spheres.
//
// Design. Everything happens in the grain's principal frame. Candidate spheres come from two
// sources: medial balls (the largest ball inside the grain that touches the surface at a sampled
// point, found by the shrinking-ball iteration) and inscribed balls about interior grid nodes.
// Each candidate also comes in two enlarged versions, radius d + δ with δ ≤ δmax: a ball whose
// centre lies at distance d from the surface and whose radius is d + δ pokes out of the grain by
// at most δ (the segment from the centre to any outside point crosses the surface at least d
// from the centre), so δmax = tolerance · d_eq / 2 bounds the outward part of the Hausdorff
// error while letting spheres fill convex edges.
//
// The union's volume is counted on a regular grid: nodes inside the grain, and outside nodes
// within δmax of its surface (no sphere can reach further). Each step adds the candidate that
// most reduces the symmetric difference (new inside nodes minus new outside nodes), until the
// volume error meets the tolerance; then, while the Hausdorff error does not, the step targets
// its worst point: a surface point far from the union, or a point of the union's boundary far
// inside the grain, and adds the candidate reaching it that gains most volume. Candidates sit
// where random seeds happened to fall, so each chosen sphere is polished by a pattern search.
//
// Determinism: one thread, a seeded SplitMix64 for the surface samples, ties broken by index.
#include "mesh/clump.hpp"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <fmt/core.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <queue>
#include <unordered_map>
#include <unordered_set>

#include "core/error.hpp"

namespace mesh {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using Point2 = K::Point_2;
using Triangle3 = K::Triangle_3;
using TriangleIt = std::vector<Triangle3>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<K, TriangleIt>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;
using diefill::InputError;

Point to_point(const geometry::Vec3& v) { return {v.x(), v.y(), v.z()}; }
geometry::Vec3 to_vec(const Point& p) { return {p.x(), p.y(), p.z()}; }

bool index_degenerate(const geometry::Triangle& t) { return t[0] == t[1] || t[1] == t[2] || t[0] == t[2]; }

// Steele, Lea & Flood's SplitMix64: a fixed, portable sequence for a given seed.
struct SplitMix64 {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }  // [0, 1)
};

// Why the mesh does not bound a solid, or empty. Triangles with a repeated vertex index (the
// poles of a welded UV sphere) bound nothing and are skipped.
std::string closure_defect(const geometry::TriMesh& m) {
  std::unordered_map<std::uint64_t, int> directed;
  for (const geometry::Triangle& t : m.triangles) {
    if (index_degenerate(t)) continue;
    for (int k = 0; k < 3; ++k)
      ++directed[(std::uint64_t(std::uint32_t(t[k])) << 32) | std::uint32_t(t[(k + 1) % 3])];
  }
  if (directed.empty()) return "the mesh has no triangles";
  std::size_t open = 0, tangled = 0;
  for (const auto& [key, count] : directed) {
    const std::uint64_t reverse = (key << 32) | (key >> 32);
    const auto it = directed.find(reverse);
    if (count > 1 || (it != directed.end() && it->second > 1))
      ++tangled;
    else if (it == directed.end())
      ++open;
  }
  if (open > 0 || tangled > 0)
    return fmt::format(
        "the mesh is not closed: {} boundary edges, {} non-manifold or "
        "inconsistently oriented edges",
        open, tangled);
  return {};
}

// Which side of the directed edge ab the point p lies on in the (y, z) plane, exactly, with p on
// the edge's line moved by (ε, ε²) (simulation of simplicity): an edge shared by two triangles
// is given to exactly one of them, so a line through an edge or vertex crosses the surface once.
int edge_side(const Point2& a, const Point2& b, const Point2& p) {
  switch (CGAL::orientation(a, b, p)) {
    case CGAL::LEFT_TURN:
      return 1;
    case CGAL::RIGHT_TURN:
      return -1;
    default:
      break;
  }
  const double uy = b.x() - a.x(), uz = b.y() - a.y();
  if (uz != 0) return uz > 0 ? -1 : 1;
  return uy > 0 ? 1 : (uy < 0 ? -1 : 0);
}

// Where the line {(x, y, z)} along x crosses triangle abc: returns the sign of the triangle's
// normal's x component (+1: the line leaves the solid there) and sets x, or returns 0.
int line_crossing(const geometry::Vec3& a, const geometry::Vec3& b, const geometry::Vec3& c, double y, double z, double& x) {
  const Point2 pa(a.y(), a.z()), pb(b.y(), b.z()), pc(c.y(), c.z()), p(y, z);
  if (CGAL::orientation(pa, pb, pc) == CGAL::COLLINEAR) return 0;
  const int s = edge_side(pa, pb, p);
  if (s == 0 || edge_side(pb, pc, p) != s || edge_side(pc, pa, p) != s) return 0;
  auto cross = [](double uy, double uz, double vy, double vz) { return uy * vz - uz * vy; };
  const double area = cross(b.y() - a.y(), b.z() - a.z(), c.y() - a.y(), c.z() - a.z());
  const double wa = cross(b.y() - y, b.z() - z, c.y() - y, c.z() - z) / area;
  const double wb = cross(c.y() - y, c.z() - z, a.y() - y, a.z() - z) / area;
  x = wa * a.x() + wb * b.x() + (1 - wa - wb) * c.x();
  return s;
}

// The grain's surface for distance and inside queries. Zero-area triangles bound nothing and
// are left out: CGAL's filtered predicates fall back to exact arithmetic on them.
class Solid {
 public:
  explicit Solid(const geometry::TriMesh& m) {
    for (const geometry::Triangle& t : m.triangles) {
      const Point a = to_point(m.vertices[t[0]]), b = to_point(m.vertices[t[1]]),
                  c = to_point(m.vertices[t[2]]);
      if (!CGAL::collinear(a, b, c)) triangles_.emplace_back(a, b, c);
    }
    tree_.insert(triangles_.begin(), triangles_.end());
    tree_.build();
    tree_.accelerate_distance_queries();
  }
  Solid(const Solid&) = delete;
  Solid& operator=(const Solid&) = delete;

  double distance(const geometry::Vec3& p) const { return std::sqrt(tree_.squared_distance(to_point(p))); }
  // With a surface point at most as far as the answer, which saves the nearest-vertex search.
  geometry::Vec3 closest(const geometry::Vec3& p, const geometry::Vec3& hint) const {
    return to_vec(tree_.closest_point(to_point(p), to_point(hint)));
  }
  // Distance from p along the unit direction u to the surface, or `otherwise` if none is hit.
  double ray_distance(const geometry::Vec3& p, const geometry::Vec3& u, double otherwise) const {
    const auto hit = tree_.first_intersection(K::Ray_3(to_point(p), to_point(p + u)));
    if (!hit) return otherwise;
    if (const Point* q = boost::get<Point>(&hit->first)) return (to_vec(*q) - p).norm();
    return otherwise;
  }

  // Winding number along the ray from p towards +x.
  bool contains(const geometry::Vec3& p) const {
    std::vector<TriangleIt> hit;
    tree_.all_intersected_primitives(K::Ray_3(to_point(p), Point(p.x() + 1, p.y(), p.z())),
                                     std::back_inserter(hit));
    int winding = 0;
    for (const TriangleIt& t : hit) {
      double x = 0;
      const int s = line_crossing(to_vec(t->vertex(0)), to_vec(t->vertex(1)), to_vec(t->vertex(2)),
                                  p.y(), p.z(), x);
      if (s != 0 && x > p.x()) winding += s;
    }
    return winding > 0;
  }

 private:
  std::vector<Triangle3> triangles_;
  Tree tree_;
};

// Grid nodes that the union of spheres may cover, for counting its volume.
constexpr std::uint8_t inside_bit = 1;   // inside the grain
constexpr std::uint8_t shell_bit = 2;    // outside, within δmax of the surface
constexpr std::uint8_t covered_bit = 4;  // inside some chosen sphere

struct Grid {
  geometry::Vec3 origin;
  double h = 0;  // spacing [m]
  std::array<int, 3> n{};
  std::vector<std::uint8_t> state;  // per node, x fastest
  long inside = 0;                  // nodes inside the grain

  std::size_t index(int i, int j, int k) const {
    return (std::size_t(k) * std::size_t(n[1]) + std::size_t(j)) * std::size_t(n[0]) +
           std::size_t(i);
  }
  geometry::Vec3 node(int i, int j, int k) const { return origin + h * geometry::Vec3(i, j, k); }
  // Node index range [first, last] whose coordinate along `axis` lies in [lo, hi].
  std::pair<int, int> range(int axis, double lo, double hi) const {
    const int first = std::max(0, int(std::ceil((lo - origin[axis]) / h)));
    const int last = std::min(n[axis] - 1, int(std::floor((hi - origin[axis]) / h)));
    return {first, last};
  }
  // Calls f(state&) for every node inside the ball (c, r).
  template <class F>
  void for_ball(const geometry::Vec3& c, double r, F&& f) {
    const auto [k0, k1] = range(2, c.z() - r, c.z() + r);
    for (int k = k0; k <= k1; ++k) {
      const double dz = origin.z() + h * k - c.z(), rz = r * r - dz * dz;
      if (rz < 0) continue;
      const double wy = std::sqrt(rz);
      const auto [j0, j1] = range(1, c.y() - wy, c.y() + wy);
      for (int j = j0; j <= j1; ++j) {
        const double dy = origin.y() + h * j - c.y(), ry = rz - dy * dy;
        if (ry < 0) continue;
        const double wx = std::sqrt(ry);
        const auto [i0, i1] = range(0, c.x() - wx, c.x() + wx);
        if (i0 > i1) continue;
        std::uint8_t* row = &state[index(i0, j, k)];
        for (int i = 0; i <= i1 - i0; ++i) f(row[i]);
      }
    }
  }
};

// Nodes classified by scan conversion: each triangle is crossed with the grid lines along x
// that pass through its (y, z) shadow, and the winding number is swept along each line. One
// pass over the triangles, exact at edges and vertices (see edge_side).
Grid make_grid(const geometry::TriMesh& m, const Solid& solid, double shell, int samples) {
  Grid g;
  const geometry::Box box = geometry::bounding_box(m);
  const geometry::Vec3 size = box.size() + geometry::Vec3::Constant(2 * shell);
  g.h = std::cbrt(size.prod() / std::max(samples, 1000));
  const double margin = shell + g.h;
  // Offsets by fractions of the golden ratio keep grid lines off the faces of axis-aligned,
  // round-numbered meshes.
  g.origin = box.lo - geometry::Vec3::Constant(margin) + g.h * geometry::Vec3(0.618034, 0.236068, 0.854102);
  for (int a = 0; a < 3; ++a) g.n[a] = int(std::ceil((box.hi[a] + margin - g.origin[a]) / g.h)) + 1;
  g.state.assign(std::size_t(g.n[0]) * std::size_t(g.n[1]) * std::size_t(g.n[2]), 0);

  std::vector<std::vector<std::pair<double, int>>> lines(std::size_t(g.n[1]) * std::size_t(g.n[2]));
  std::vector<std::uint8_t> near(g.state.size(), 0);
  for (const geometry::Triangle& t : m.triangles) {
    const geometry::Vec3 &a = m.vertices[t[0]], &b = m.vertices[t[1]], &c = m.vertices[t[2]];
    const geometry::Vec3 lo = a.cwiseMin(b).cwiseMin(c), hi = a.cwiseMax(b).cwiseMax(c);
    const auto [j0, j1] = g.range(1, lo.y(), hi.y());
    const auto [k0, k1] = g.range(2, lo.z(), hi.z());
    for (int k = k0; k <= k1; ++k)
      for (int j = j0; j <= j1; ++j) {
        double x = 0;
        const geometry::Vec3 p = g.node(0, j, k);
        if (const int s = line_crossing(a, b, c, p.y(), p.z(), x))
          lines[std::size_t(k) * std::size_t(g.n[1]) + std::size_t(j)].emplace_back(x, s);
      }
    // Nodes that might lie within `shell` of this triangle, for the exact test below.
    const auto [i0, i1] = g.range(0, lo.x() - shell, hi.x() + shell);
    const auto [nj0, nj1] = g.range(1, lo.y() - shell, hi.y() + shell);
    const auto [nk0, nk1] = g.range(2, lo.z() - shell, hi.z() + shell);
    for (int k = nk0; k <= nk1; ++k)
      for (int j = nj0; j <= nj1; ++j)
        for (int i = i0; i <= i1; ++i) near[g.index(i, j, k)] = 1;
  }
  for (int k = 0; k < g.n[2]; ++k)
    for (int j = 0; j < g.n[1]; ++j) {
      auto& line = lines[std::size_t(k) * std::size_t(g.n[1]) + std::size_t(j)];
      std::sort(line.begin(), line.end());
      int winding = 0;
      std::size_t next = 0;
      for (int i = 0; i < g.n[0]; ++i) {
        const double x = g.origin.x() + g.h * i;
        for (; next < line.size() && line[next].first < x; ++next) winding -= line[next].second;
        std::uint8_t& s = g.state[g.index(i, j, k)];
        if (winding > 0) {
          s = inside_bit;
          ++g.inside;
        } else if (near[g.index(i, j, k)] && solid.distance(g.node(i, j, k)) <= shell) {
          s = shell_bit;
        }
      }
    }
  return g;
}

struct Ball {
  geometry::Vec3 c;
  double r;
};

// Largest ball inside the solid that touches the surface at p, where the inward normal is n:
// the shrinking-ball iteration of Ma, Bae & Varshney (2012), which shrinks the ball through p
// until its nearest surface point is p itself. Its centre approximates a medial-axis point.
// The ball cannot be wider than the chord along n, which gives the first radius: deep closest-
// point queries are the cost here, and on a convex grain the first one is the last.
std::optional<Ball> medial_ball(const Solid& solid, const geometry::Vec3& p, const geometry::Vec3& n, double r_max) {
  const double lift = 1e-9 * r_max;  // off p's own triangle
  double r = 0.5 * (lift + solid.ray_distance(p + lift * n, n, 2 * r_max));
  const double r0 = r;
  for (int iteration = 0; iteration < 50; ++iteration) {
    const geometry::Vec3 c = p + r * n;
    const geometry::Vec3 q = solid.closest(c, p);
    const double d = (c - q).norm();
    if (d >= r * (1 - 1e-6)) return Ball{c, d};
    const double denominator = 2 * n.dot(q - p);
    if (denominator <= 0) return std::nullopt;
    r = std::min(r * (1 - 1e-9), (q - p).squaredNorm() / denominator);
    if (r <= r0 * 1e-6) return std::nullopt;
  }
  return std::nullopt;
}

// A surface point where the Hausdorff distance is measured, with its inward direction.
struct Probe {
  geometry::Vec3 p, inward;
  double gap = std::numeric_limits<double>::infinity();  // min_i |p − c_i| − r_i
};

// A point on a chosen sphere; it is on the union's boundary while no other sphere holds it.
struct BoundaryPoint {
  geometry::Vec3 p;
  double distance;  // to the grain's surface
  bool exposed;
};

// Fixed directions on the unit sphere (a Fibonacci lattice), for the union's boundary.
std::vector<geometry::Vec3> fibonacci_directions(int count) {
  std::vector<geometry::Vec3> out;
  const double golden = std::numbers::pi * (3 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1 - (2 * i + 1.0) / count, rho = std::sqrt(1 - z * z);
    out.emplace_back(rho * std::cos(golden * i), rho * std::sin(golden * i), z);
  }
  return out;
}

// The greedy selection and its running error state.
class Builder {
 public:
  Builder(const geometry::TriMesh& m, const ClumpOptions& o, double d_eq)
      : mesh_(m),
        solid_(m),
        options_(o),
        d_eq_(d_eq),
        delta_(0.5 * o.tolerance * d_eq),
        grid_(make_grid(m, solid_, delta_ * 1.001, o.samples)),
        directions_(fibonacci_directions(256)) {
    if (grid_.inside == 0)
      throw InputError(
          "", "samples",
          fmt::format("no node of the {} sample grid lies inside the grain", o.samples),
          "The grain is thin compared with its bounding box: give more samples");
    make_probes_and_medial_candidates();
    make_grid_candidates();
    for (std::size_t i = 0; i < pool_.size(); ++i) heap_.emplace(gain(pool_[i]), -long(i));
  }

  // Adds spheres until both errors meet the tolerance; the history records every step.
  void run(geometry::ClumpTemplate& out) {
    const double tol = options_.tolerance;
    while (int(spheres_.size()) < options_.max_spheres) {
      if (!spheres_.empty() && volume_error() <= tol && hausdorff_error() <= tol) break;
      std::optional<Ball> next;
      if (spheres_.empty() || volume_error() > tol) next = best_for_volume();
      if (!next && !spheres_.empty() && hausdorff_error() > tol) next = best_for_hausdorff();
      if (!next) break;
      add(*next);
      out.history.push_back({int(spheres_.size()), volume_error(), hausdorff_error()});
    }
    for (const Ball& b : spheres_) out.spheres.push_back({b.c, b.r});
    out.union_volume_m3 =
        out.mesh_volume_m3 * double(covered_inside_ + covered_shell_) / double(grid_.inside);
    out.volume_error = volume_error();
    out.hausdorff_error = hausdorff_error();
  }

 private:
  double volume_error() const {
    return std::abs(double(covered_inside_ + covered_shell_ - grid_.inside)) / double(grid_.inside);
  }
  double hausdorff_error() const {
    double worst = 0;
    for (const Probe& p : probes_) worst = std::max(worst, std::abs(p.gap));
    for (const BoundaryPoint& b : boundary_)
      if (b.exposed) worst = std::max(worst, b.distance);
    return worst / d_eq_;
  }

  // Reduction of the symmetric difference between grain and union, in grid nodes.
  long gain(const Ball& b) {
    long g = 0;
    grid_.for_ball(b.c, b.r, [&](std::uint8_t s) {
      if (!(s & covered_bit)) g += (s & inside_bit) ? 1 : ((s & shell_bit) ? -1 : 0);
    });
    return g;
  }

  // Candidates about centre c at distance d from the surface: inscribed, and poking out by up
  // to δmax.
  void push_candidates(const geometry::Vec3& c, double d, std::vector<Ball>& to) const {
    for (const double f : {0.0, 0.5, 1.0})
      if (d + f * delta_ > 0) to.push_back({c, d + f * delta_});
  }

  // Pool candidates, one per grid cell of centre and radius: on a round grain thousands of
  // medial balls coincide, and polishing recovers what the rounding loses.
  void pool_candidates(const geometry::Vec3& c, double d) {
    std::uint64_t key = 0;
    for (const double v :
         {c.x() - grid_.origin.x(), c.y() - grid_.origin.y(), c.z() - grid_.origin.z(), d})
      key = (key << 16) | (std::uint64_t(std::lround(v / grid_.h)) & 0xffff);
    if (pooled_.insert(key).second) push_candidates(c, d, pool_);
  }

  void make_probes_and_medial_candidates() {
    // Vertices, with angle-weighted normals: sharp corners are where the error peaks.
    std::vector<geometry::Vec3> normals(mesh_.vertices.size(), geometry::Vec3::Zero());
    std::vector<double> cumulative_area;
    double area = 0;
    for (const geometry::Triangle& t : mesh_.triangles) {
      const geometry::Vec3 &a = mesh_.vertices[t[0]], &b = mesh_.vertices[t[1]], &c = mesh_.vertices[t[2]];
      const geometry::Vec3 cross = (b - a).cross(c - a);
      area += 0.5 * cross.norm();
      cumulative_area.push_back(area);
      if (cross.norm() == 0) continue;
      const geometry::Vec3 n = cross.normalized();
      for (int k = 0; k < 3; ++k) {
        const geometry::Vec3 u = mesh_.vertices[t[(k + 1) % 3]] - mesh_.vertices[t[k]];
        const geometry::Vec3 v = mesh_.vertices[t[(k + 2) % 3]] - mesh_.vertices[t[k]];
        const double angle = std::atan2(u.cross(v).norm(), u.dot(v));
        normals[std::size_t(t[k])] += angle * n;
      }
    }
    for (std::size_t v = 0; v < mesh_.vertices.size(); ++v)
      if (normals[v].norm() > 0) probes_.push_back({mesh_.vertices[v], -normals[v].normalized()});

    // Area-weighted random surface points: probes, and seeds of medial balls.
    SplitMix64 rng{options_.seed};
    const double r_max = geometry::bounding_box(mesh_).size().norm();
    constexpr int surface_samples = 3000, medial_seeds = 1500;
    for (int s = 0; s < surface_samples; ++s) {
      const double pick = rng.uniform() * area;
      const auto f =
          std::size_t(std::upper_bound(cumulative_area.begin(), cumulative_area.end(), pick) -
                      cumulative_area.begin());
      const geometry::Triangle& t = mesh_.triangles[std::min(f, mesh_.triangles.size() - 1)];
      const geometry::Vec3 &a = mesh_.vertices[t[0]], &b = mesh_.vertices[t[1]], &c = mesh_.vertices[t[2]];
      const geometry::Vec3 cross = (b - a).cross(c - a);
      const double u = std::sqrt(rng.uniform()), v = rng.uniform();
      if (cross.norm() == 0) continue;
      const geometry::Vec3 p = a * (1 - u) + b * (u * (1 - v)) + c * (u * v);
      const geometry::Vec3 inward = -cross.normalized();
      probes_.push_back({p, inward});
      if (s < medial_seeds)
        if (const auto ball = medial_ball(solid_, p, inward, r_max))
          pool_candidates(ball->c, ball->r);
    }
  }

  // Inscribed balls about a sub-lattice of about a thousand interior nodes.
  void make_grid_candidates() {
    const int stride = std::max(1, int(std::lround(std::cbrt(double(grid_.inside) / 1000.0))));
    for (int k = 0; k < grid_.n[2]; k += stride)
      for (int j = 0; j < grid_.n[1]; j += stride)
        for (int i = 0; i < grid_.n[0]; i += stride)
          if (grid_.state[grid_.index(i, j, k)] & inside_bit) {
            const geometry::Vec3 c = grid_.node(i, j, k);
            pool_candidates(c, solid_.distance(c));
          }
  }

  // The pool candidate with the largest gain (lazy greedy: a stale gain is re-evaluated only
  // when it reaches the top), or none when no candidate reduces the symmetric difference.
  std::optional<Ball> best_for_volume() {
    while (!heap_.empty()) {
      const auto [stale, key] = heap_.top();
      heap_.pop();
      const long fresh = gain(pool_[std::size_t(-key)]);
      if (heap_.empty() || fresh >= heap_.top().first) {
        if (fresh > 0)
          return polish(pool_[std::size_t(-key)], fresh, [](const Ball&) { return true; });
        heap_.emplace(fresh, key);
        return std::nullopt;
      }
      heap_.emplace(fresh, key);
    }
    return std::nullopt;
  }

  // Among the candidates that bring the worst point of the Hausdorff distance within half the
  // tolerance (a surface point) or that swallow it (a boundary point deep inside the grain), the
  // one with the largest gain. Besides the pool, candidates are made at the worst point itself.
  std::optional<Ball> best_for_hausdorff() {
    std::size_t worst_probe = 0;
    for (std::size_t i = 1; i < probes_.size(); ++i)
      if (std::abs(probes_[i].gap) > std::abs(probes_[worst_probe].gap)) worst_probe = i;
    std::optional<std::size_t> worst_boundary;
    for (std::size_t i = 0; i < boundary_.size(); ++i)
      if (boundary_[i].exposed &&
          (!worst_boundary || boundary_[i].distance > boundary_[*worst_boundary].distance))
        worst_boundary = i;

    std::vector<Ball> local;
    std::function<bool(const Ball&)> reaches;
    if (!worst_boundary ||
        std::abs(probes_[worst_probe].gap) >= boundary_[*worst_boundary].distance) {
      const Probe target = probes_[worst_probe];
      const double reach = 0.5 * options_.tolerance * d_eq_;
      reaches = [target, reach](const Ball& b) { return (target.p - b.c).norm() - b.r <= reach; };
      // Centres stepped inward from the point along its normal, from half the grain down.
      for (double t = 0.5 * d_eq_; t > 1e-3 * reach; t *= 0.7) {
        const geometry::Vec3 c = target.p + t * target.inward;
        if (solid_.contains(c)) push_candidates(c, solid_.distance(c), local);
      }
    } else {
      const geometry::Vec3 q = boundary_[*worst_boundary].p;
      reaches = [q](const Ball& b) { return (q - b.c).norm() < b.r; };
      if (solid_.contains(q)) push_candidates(q, solid_.distance(q), local);
    }
    std::optional<Ball> best;
    long best_gain = std::numeric_limits<long>::min();
    for (const std::vector<Ball>* set : {&pool_, &local})
      for (const Ball& b : *set)
        if (reaches(b))
          if (const long g = gain(b); g > best_gain) {
            best_gain = g;
            best = b;
          }
    if (!best) return std::nullopt;
    return polish(*best, best_gain, reaches);
  }

  // Candidates sit where samples happened to fall (a medial ball is tangent at its random
  // seed point), so the chosen one is refined: pattern search over its centre, in steps from
  // one grid spacing down to an eighth, and over its protrusion, keeping `accept` true. A step
  // shorter than the centre's distance to the surface keeps the centre inside.
  template <class Accept>
  Ball polish(Ball b, long g, const Accept& accept) {
    double d = solid_.distance(b.c);
    for (double step = grid_.h; step >= grid_.h / 8; step /= 2) {
      if (step >= d) continue;
      for (int iteration = 0; iteration < 32; ++iteration) {
        Ball best = b;
        long best_gain = g;
        double best_d = d;
        for (int move = 0; move < 7; ++move) {
          geometry::Vec3 c = b.c;
          if (move > 0) c[(move - 1) / 2] += (move % 2 ? step : -step);
          const double dc = move > 0 ? solid_.distance(c) : d;
          for (const double f : {0.0, 0.25, 0.5, 0.75, 1.0}) {
            const Ball trial{c, dc + f * delta_};
            if (trial.r <= 0 || !accept(trial)) continue;
            if (const long tg = gain(trial); tg > best_gain) {
              best = trial;
              best_gain = tg;
              best_d = dc;
            }
          }
        }
        if (best_gain == g) break;
        b = best;
        g = best_gain;
        d = best_d;
      }
    }
    return b;
  }

  void add(const Ball& b) {
    grid_.for_ball(b.c, b.r, [&](std::uint8_t& s) {
      if (s & covered_bit) return;
      if (s & inside_bit)
        ++covered_inside_;
      else if (s & shell_bit)
        ++covered_shell_;
      s |= covered_bit;
    });
    for (Probe& p : probes_) p.gap = std::min(p.gap, (p.p - b.c).norm() - b.r);
    for (BoundaryPoint& q : boundary_)
      if (q.exposed && (q.p - b.c).norm() < b.r) q.exposed = false;
    for (const geometry::Vec3& u : directions_) {
      const geometry::Vec3 p = b.c + b.r * u;
      const bool hidden = std::any_of(spheres_.begin(), spheres_.end(),
                                      [&](const Ball& s) { return (p - s.c).norm() < s.r; });
      if (!hidden) boundary_.push_back({p, solid_.distance(p), true});
    }
    spheres_.push_back(b);
  }

  const geometry::TriMesh& mesh_;
  Solid solid_;
  const ClumpOptions& options_;
  double d_eq_, delta_;
  Grid grid_;
  std::vector<geometry::Vec3> directions_;
  std::vector<Probe> probes_;
  std::vector<Ball> pool_;
  std::unordered_set<std::uint64_t> pooled_;         // cells of pool_, see pool_candidates
  std::priority_queue<std::pair<long, long>> heap_;  // (gain, −index): ties go to the lower index
  std::vector<Ball> spheres_;
  std::vector<BoundaryPoint> boundary_;
  long covered_inside_ = 0, covered_shell_ = 0;
};

// Per-triangle subexpressions of Eberly's integrals.
struct Sub {
  double f1, f2, f3, g0, g1, g2;
  Sub(double w0, double w1, double w2) {
    const double t0 = w0 + w1, t1 = w0 * w0, t2 = t1 + w1 * t0;
    f1 = t0 + w2;
    f2 = t2 + w2 * f1;
    f3 = w0 * t1 + w1 * t2 + w2 * f2;
    g0 = f2 + w0 * (f1 + w0);
    g1 = f2 + w1 * (f1 + w1);
    g2 = f2 + w2 * (f1 + w2);
  }
};

}  // namespace

MassProperties mass_properties(const geometry::TriMesh& m) {
  // Integrals about the bounding-box centre, so that a grain far from the origin loses no digits
  // to cancellation.
  const geometry::Box box = geometry::bounding_box(m);
  const geometry::Vec3 ref = box.empty() ? geometry::Vec3::Zero() : geometry::Vec3(0.5 * (box.lo + box.hi));
  // 1, x, y, z, x², y², z², xy, yz, zx
  std::array<double, 10> in{};
  for (const geometry::Triangle& t : m.triangles) {
    const geometry::Vec3 p0 = m.vertices[t[0]] - ref, p1 = m.vertices[t[1]] - ref,
                         p2 = m.vertices[t[2]] - ref;
    const geometry::Vec3 d = (p1 - p0).cross(p2 - p0);
    const Sub x(p0.x(), p1.x(), p2.x()), y(p0.y(), p1.y(), p2.y()), z(p0.z(), p1.z(), p2.z());
    in[0] += d.x() * x.f1;
    in[1] += d.x() * x.f2;
    in[2] += d.y() * y.f2;
    in[3] += d.z() * z.f2;
    in[4] += d.x() * x.f3;
    in[5] += d.y() * y.f3;
    in[6] += d.z() * z.f3;
    in[7] += d.x() * (p0.y() * x.g0 + p1.y() * x.g1 + p2.y() * x.g2);
    in[8] += d.y() * (p0.z() * y.g0 + p1.z() * y.g1 + p2.z() * y.g2);
    in[9] += d.z() * (p0.x() * z.g0 + p1.x() * z.g1 + p2.x() * z.g2);
  }
  const double scale[10] = {1 / 6.0,  1 / 24.0, 1 / 24.0,  1 / 24.0,  1 / 60.0,
                            1 / 60.0, 1 / 60.0, 1 / 120.0, 1 / 120.0, 1 / 120.0};
  for (int i = 0; i < 10; ++i) in[std::size_t(i)] *= scale[i];

  MassProperties mp;
  mp.volume = in[0];
  if (mp.volume == 0) return mp;
  const geometry::Vec3 c(in[1] / in[0], in[2] / in[0], in[3] / in[0]);
  const double v = in[0];
  Eigen::Matrix3d& I = mp.inertia_per_density;
  I(0, 0) = in[5] + in[6] - v * (c.y() * c.y() + c.z() * c.z());
  I(1, 1) = in[4] + in[6] - v * (c.z() * c.z() + c.x() * c.x());
  I(2, 2) = in[4] + in[5] - v * (c.x() * c.x() + c.y() * c.y());
  I(0, 1) = I(1, 0) = -(in[7] - v * c.x() * c.y());
  I(1, 2) = I(2, 1) = -(in[8] - v * c.y() * c.z());
  I(0, 2) = I(2, 0) = -(in[9] - v * c.z() * c.x());
  mp.centroid = c + ref;
  return mp;
}

geometry::ClumpTemplate make_clump(const geometry::TriMesh& grain, const ClumpOptions& options) {
  if (!(options.tolerance > 0 && options.tolerance < 1))
    throw InputError("", "tolerance", fmt::format("{} is not between 0 and 1", options.tolerance),
                     "Give a relative tolerance such as 0.05");
  if (options.max_spheres < 1)
    throw InputError("", "max_spheres", fmt::format("{} is less than one", options.max_spheres),
                     "Allow at least one sphere");
  if (const std::string defect = closure_defect(grain); !defect.empty())
    throw InputError("", "mesh", defect,
                     "Repair the grain mesh first (diefill sdf shows the checks)");
  const MassProperties mp = mass_properties(grain);
  if (!(mp.volume > 0))
    throw InputError("", "mesh", "the mesh is oriented inward (its volume is negative)",
                     "Repair the grain mesh first, which orients it outward");

  geometry::ClumpTemplate out;
  out.tolerance = options.tolerance;
  out.mesh_volume_m3 = mp.volume;
  out.mesh_centroid = mp.centroid;
  out.equivalent_diameter_m = std::cbrt(6 * mp.volume / std::numbers::pi);

  // Principal axes: ascending moments, each axis's largest component positive, right-handed.
  // An isotropic grain (a sphere, a cube) keeps the mesh's own axes, which are as principal as any.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(mp.inertia_per_density);
  out.inertia_principal_per_density = eigen.eigenvalues();
  Eigen::Matrix3d axes = eigen.eigenvectors();
  const geometry::Vec3& moments = out.inertia_principal_per_density;
  if (moments.maxCoeff() - moments.minCoeff() <= 1e-9 * moments.maxCoeff()) axes.setIdentity();
  for (int a = 0; a < 3; ++a) {
    Eigen::Index largest = 0;
    axes.col(a).cwiseAbs().maxCoeff(&largest);
    if (axes(largest, a) < 0) axes.col(a) *= -1;
  }
  if (axes.determinant() < 0) axes.col(2) *= -1;
  out.rotation_mesh_to_principal = axes.transpose();

  geometry::TriMesh principal = grain;
  for (geometry::Vec3& v : principal.vertices) v = out.rotation_mesh_to_principal * (v - mp.centroid);

  Builder builder(principal, options, out.equivalent_diameter_m);
  builder.run(out);
  if (out.volume_error > options.tolerance || out.hausdorff_error > options.tolerance) {
    auto score = [](const geometry::ClumpStep& s) { return std::max(s.volume_error, s.hausdorff_error); };
    const geometry::ClumpStep best = out.history.empty()
                                         ? geometry::ClumpStep{}
                                         : *std::min_element(out.history.begin(), out.history.end(),
                                                             [&](const geometry::ClumpStep& a, const geometry::ClumpStep& b) {
                                                               return score(a) < score(b);
                                                             });
    const bool stalled = int(out.spheres.size()) < options.max_spheres;
    throw InputError(
        "", "tolerance",
        fmt::format("{} spheres do not reach the tolerance {}{}: the closest were {} spheres, with "
                    "volume error {:.3g} and Hausdorff error {:.3g}",
                    out.spheres.size(), options.tolerance,
                    stalled ? " and no candidate sphere improves them" : "", best.spheres,
                    best.volume_error, best.hausdorff_error),
        stalled
            ? fmt::format("Raise the tolerance to at least {:.3g}", score(best))
            : fmt::format("Allow more spheres (--max-spheres, now {}) or raise the tolerance to "
                          "at least {:.3g}",
                          options.max_spheres, score(best)));
  }
  return out;
}

std::string clump_json(const geometry::ClumpTemplate& c) {
  nlohmann::ordered_json j;
  j["spheres"] = nlohmann::ordered_json::array();
  for (const geometry::ClumpSphere& s : c.spheres)
    j["spheres"].push_back({s.centre.x(), s.centre.y(), s.centre.z(), s.radius});
  j["mesh_volume_m3"] = c.mesh_volume_m3;
  const geometry::Vec3& I = c.inertia_principal_per_density;
  j["inertia_principal_per_density"] = {I.x(), I.y(), I.z()};
  j["union_volume_m3"] = c.union_volume_m3;
  j["volume_error"] = c.volume_error;
  j["hausdorff_error"] = c.hausdorff_error;
  j["tolerance"] = c.tolerance;
  j["equivalent_diameter_m"] = c.equivalent_diameter_m;
  j["mesh_centroid_m"] = {c.mesh_centroid.x(), c.mesh_centroid.y(), c.mesh_centroid.z()};
  const Eigen::Matrix3d& R = c.rotation_mesh_to_principal;
  j["rotation"] = nlohmann::ordered_json::array();
  for (int r = 0; r < 3; ++r) j["rotation"].push_back({R(r, 0), R(r, 1), R(r, 2)});
  j["history"] = nlohmann::ordered_json::array();
  for (const geometry::ClumpStep& s : c.history)
    j["history"].push_back({{"spheres", s.spheres},
                            {"volume_error", s.volume_error},
                            {"hausdorff_error", s.hausdorff_error}});
  return j.dump(2);
}

}  // namespace mesh
