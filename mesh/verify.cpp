#include "mesh/verify.hpp"

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
        const Vec3 p = seg.a + (seg.b - seg.a) * (double(k) / steps);
        auto& bucket = cells_[key(cell_of(p))];
        if (bucket.empty() || bucket.back() != s) bucket.push_back(s);
      }
    }
  }
  bool near(const Vec3& p) const {
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
  std::array<std::int64_t, 3> cell_of(const Vec3& p) const {
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

}  // namespace

SdfVerification verify_sdf(const SdfGrid& sdf, const TriMesh& mesh, const ExactSurface& exact,
                           std::size_t samples, std::uint64_t seed, double sharp_angle_deg) {
  SdfVerification out;
  const double h = sdf.voxel_size();
  const std::vector<Vec3> voxels = sdf.active_voxel_positions();
  if (voxels.empty() || samples == 0) return out;
  SegmentProximity sharp(sharp_edges(mesh, sharp_angle_deg), h);
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> pick(0, voxels.size() - 1);
  std::uniform_real_distribution<double> offset(0.0, 1.0);
  double error_sum = 0.0;
  // Rejection sampling: a uniform voxel, a uniform point in the cell above it, kept when all
  // eight corners are in the band. Bounded so that a degenerate band cannot loop forever.
  for (std::size_t attempt = 0; out.samples < samples && attempt < 50 * samples; ++attempt) {
    const Vec3 p = voxels[pick(rng)] + h * Vec3(offset(rng), offset(rng), offset(rng));
    if (!sdf.in_band(p)) continue;
    ++out.samples;
    const double reference = exact.signed_distance(p);
    const double value = sdf.sample(p);
    const double error = std::abs(value - reference) / h;
    error_sum += error;
    out.max_error_voxels = std::max(out.max_error_voxels, error);
    if (!sharp.near(p)) {
      ++out.smooth_samples;
      if (error > out.max_error_smooth_voxels) {
        out.max_error_smooth_voxels = error;
        out.worst_smooth_point = p;
      }
    }
    if (std::abs(reference) > 0.5 * h) {
      ++out.sign_checked;
      if ((value < 0) != (reference < 0)) ++out.sign_disagreements;
    }
  }
  out.mean_error_voxels = out.samples ? error_sum / out.samples : 0.0;
  return out;
}

}  // namespace mesh
