#include "mesh/verify.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <unordered_map>

#include "mesh/geometry.hpp"

namespace mesh {

namespace {

// Buckets of sharp-edge segments on a uniform grid, to ask "is p within r of a sharp edge?"
// in constant time; the cell size is r, so the 27 surrounding cells hold every candidate.
class SegmentProximity {
 public:
  SegmentProximity(std::vector<Segment> segments, double radius)
      : segments_(std::move(segments)), radius_(radius) {
    for (std::size_t s = 0; s < segments_.size(); ++s) {
      const Segment& seg = segments_[s];
      const double length = (seg.b - seg.a).norm();
      const int steps = std::max(1, int(std::ceil(length / (0.5 * radius_))));
      for (int k = 0; k <= steps; ++k) {
        const geometry::Vec3 p = seg.a + (seg.b - seg.a) * (double(k) / steps);
        auto& bucket = cells_[key(cell_of(p))];
        if (bucket.empty() || bucket.back() != s) bucket.push_back(s);
      }
    }
  }
  bool near(const geometry::Vec3& p) const {
    const auto c = cell_of(p);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          auto it = cells_.find(key({c[0] + dx, c[1] + dy, c[2] + dz}));
          if (it == cells_.end()) continue;
          for (std::size_t s : it->second)
            if (distance_to_segment(p, segments_[s].a, segments_[s].b) <= radius_) return true;
        }
    return false;
  }

 private:
  std::array<std::int64_t, 3> cell_of(const geometry::Vec3& p) const {
    return {std::int64_t(std::floor(p.x() / radius_)), std::int64_t(std::floor(p.y() / radius_)),
            std::int64_t(std::floor(p.z() / radius_))};
  }
  static std::uint64_t key(const std::array<std::int64_t, 3>& c) {
    return (std::uint64_t(c[0] & 0x1FFFFF) << 42) | (std::uint64_t(c[1] & 0x1FFFFF) << 21) |
           std::uint64_t(c[2] & 0x1FFFFF);
  }
  std::vector<Segment> segments_;
  double radius_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells_;
};

// Points within two voxels of the sharp edges, uniform along them (SdfVerification).
void verify_beside_sharp_edges(const geometry::WallField& field, const ExactSurface& exact, const std::vector<Segment>& edges,
                               std::size_t samples, std::mt19937_64& rng, SdfVerification& out) {
  std::vector<double> running;
  double length = 0;
  for (const Segment& e : edges) running.push_back(length += (e.b - e.a).norm());
  if (edges.empty() || length <= 0) return;
  const double h = field.voxel;
  std::uniform_real_distribution<double> along(0.0, length), unit(-1.0, 1.0), reach(0.0, 2.0 * h);
  bool found_one = false;
  for (std::size_t attempt = 0; out.sharp_samples < samples && attempt < 50 * samples; ++attempt) {
    const double at = along(rng);
    const std::size_t k = std::min(edges.size() - 1, std::size_t(std::upper_bound(running.begin(), running.end(), at) - running.begin()));
    const Segment& e = edges[k];
    const double start = k == 0 ? 0.0 : running[k - 1];
    const geometry::Vec3 on_edge = e.a + (e.b - e.a) * ((at - start) / std::max(1e-300, running[k] - start));
    const geometry::Vec3 direction(unit(rng), unit(rng), unit(rng));
    if (direction.norm() < 1e-3) continue;
    const geometry::Vec3 p = on_edge + reach(rng) * direction.normalized();
    const double reference = exact.signed_distance(p);
    if (std::abs(reference) <= 0.5 * h) continue;
    ++out.sharp_samples;
    const bool inside = reference < 0;
    bool wrong = (field.signed_distance(p) < 0) != inside;
    out.sharp_sign_disagreements += wrong;
    geometry::SurfacePoint contacts[4];
    const int count = field.local_minima(p, 2.0 * h, contacts, 4);
    for (int c = 0; c < count; ++c)
      if ((contacts[c].distance < 0) != inside) ++out.sharp_contact_sign_disagreements, wrong = true;
    if (wrong && !found_one) out.first_sharp_disagreement = p, found_one = true;
  }
}

}  // namespace

SdfVerification verify_sdf(const geometry::WallField& field, const geometry::TriMesh& mesh, const ExactSurface& exact,
                           std::size_t samples, std::uint64_t seed, double sharp_angle_deg) {
  SdfVerification out;
  const double h = field.voxel;
  // Band voxels (those with a closest triangle), drawn uniformly without listing them all:
  // a running count per brick, then the n-th band voxel inside the brick found.
  struct BrickCount {
    std::array<int, 3> origin;  // first voxel of the brick
    std::int32_t brick;
  };
  std::vector<BrickCount> bricks;
  std::vector<std::size_t> running;  // band voxels in bricks before and including this one
  std::size_t total = 0;
  for (int bi = 0; bi < field.brick_count[0]; ++bi)
    for (int bj = 0; bj < field.brick_count[1]; ++bj)
      for (int bk = 0; bk < field.brick_count[2]; ++bk) {
        const std::int32_t brick =
            field.brick_of_cell[(std::size_t(bi) * std::size_t(field.brick_count[1]) + std::size_t(bj)) *
                                    std::size_t(field.brick_count[2]) + std::size_t(bk)];
        if (brick < 0) continue;
        std::size_t in_band = 0;
        for (std::size_t n = 0; n < 512; ++n) in_band += field.closest[std::size_t(brick) * 512 + n] >= 0;
        if (in_band == 0) continue;
        total += in_band;
        bricks.push_back({{(field.brick_min[0] + bi) * 8, (field.brick_min[1] + bj) * 8,
                           (field.brick_min[2] + bk) * 8},
                          brick});
        running.push_back(total);
      }
  auto band_voxel = [&](std::size_t index) {
    const std::size_t b = std::size_t(std::upper_bound(running.begin(), running.end(), index) - running.begin());
    std::size_t skip = index - (b == 0 ? 0 : running[b - 1]);
    for (std::size_t n = 0; n < 512; ++n)
      if (field.closest[std::size_t(bricks[b].brick) * 512 + n] >= 0 && skip-- == 0)
        return geometry::Vec3(h * (bricks[b].origin[0] + int(n >> 6)), h * (bricks[b].origin[1] + int(n >> 3 & 7)),
                              h * (bricks[b].origin[2] + int(n & 7)));
    return geometry::Vec3(geometry::Vec3::Zero());
  };
  if (total == 0 || samples == 0) return out;
  SegmentProximity sharp(sharp_edges(mesh, sharp_angle_deg), h);
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> pick(0, total - 1);
  std::uniform_real_distribution<double> offset(0.0, 1.0);
  double query_sum = 0.0, grid_sum = 0.0;
  // Errors count where they matter, signs everywhere: the wall query answers for grain centres,
  // which reach at most a voxel into the solid before the overlap check stops a run (the default
  // voxel is a quarter radius, the stop limit a quarter radius of overlap); deeper in the
  // three-voxel band its minima can miss a closest face the corners do not lead to.
  auto record = [&](SdfErrors& e, double value, double reference, bool smooth, const geometry::Vec3& p,
                    double& sum, bool counted) {
    const double error = counted ? std::abs(value - reference) / h : 0.0;
    sum += error;
    e.max_voxels = std::max(e.max_voxels, error);
    if (smooth && error > e.max_smooth_voxels) {
      e.max_smooth_voxels = error;
      e.worst_smooth_point = p;
    }
    if (std::abs(reference) > 0.5 * h && (value < 0) != (reference < 0) && e.sign_disagreements++ == 0)
      e.first_sign_disagreement = p;
  };
  // Rejection sampling: a uniform band voxel, a uniform point in the cell above it, kept when
  // all eight corners of that cell are in the band. Bounded attempts.
  for (std::size_t attempt = 0; out.samples < samples && attempt < 50 * samples; ++attempt) {
    const geometry::Vec3 p = band_voxel(pick(rng)) + h * geometry::Vec3(offset(rng), offset(rng), offset(rng));
    if (!field.band_cell(p)) continue;
    const double grid_value = field.trilinear(p);
    ++out.samples;
    const double reference = exact.signed_distance(p);
    const bool smooth = !sharp.near(p);
    out.smooth_samples += smooth;
    out.sign_checked += std::abs(reference) > 0.5 * h;
    const bool reachable = reference > -h;
    out.reachable_samples += reachable;
    record(out.query, field.signed_distance(p), reference, smooth, p, query_sum, reachable);
    record(out.grid, grid_value, reference, smooth, p, grid_sum, true);
  }
  if (out.samples) {
    out.query.mean_voxels = query_sum / double(std::max<std::size_t>(1, out.reachable_samples));
    out.grid.mean_voxels = grid_sum / double(out.samples);
  }
  verify_beside_sharp_edges(field, exact, sharp_edges(mesh, sharp_angle_deg), samples, rng, out);
  return out;
}

}  // namespace mesh
