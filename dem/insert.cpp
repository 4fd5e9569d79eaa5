#include "dem/insert.hpp"

#include <cmath>
#include <numbers>
#include <unordered_map>

#include "dem/bodies.hpp"
#include "dem/walls.hpp"

namespace dem {

namespace {

// Spatial hash of every sphere present, to reject overlaps; exact for a candidate and a
// sphere whose radii add up to no more than the cell.
class Occupancy {
 public:
  Occupancy(const State& s, double cell) : s_(s), cell_(cell) {
    for (std::size_t i = 0; i < s.size(); ++i) add(i);
  }
  void add(std::size_t i) { grid_[key(s_.x[i])].push_back(std::int32_t(i)); }
  bool free_at(const Vec3& p, double r) const {
    const auto c = (p / cell_).array().floor().cast<std::int64_t>();
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const Vec3 q = (Vec3(double(c.x() + dx), double(c.y() + dy), double(c.z() + dz)) + Vec3::Constant(0.5)) * cell_;
          auto it = grid_.find(key(q));
          if (it == grid_.end()) continue;
          for (std::int32_t j : it->second) {
            const double reach = r + s_.radius[std::size_t(j)];
            if ((s_.x[std::size_t(j)] - p).squaredNorm() < reach * reach) return false;
          }
        }
    return true;
  }

 private:
  std::uint64_t key(const Vec3& p) const {
    const auto c = (p / cell_).array().floor().cast<std::int64_t>();
    return (std::uint64_t(c.x() & 0x1FFFFF) << 42) | (std::uint64_t(c.y() & 0x1FFFFF) << 21) | std::uint64_t(c.z() & 0x1FFFFF);
  }
  const State& s_;
  double cell_;
  std::unordered_map<std::uint64_t, std::vector<std::int32_t>> grid_;
};

// Whether a sphere at p of radius r passes the region's tests other than overlap.
bool admissible(const InsertRegion& region, const State& s, const Vec3& p, double r) {
  if (region.accept && !region.accept(p, r)) return false;
  if (region.inside && region.inside->signed_distance(p) > -r) return false;
  if (region.clear_of_walls && wall_distance(*region.clear_of_walls, s.time, p) < r) return false;
  return true;
}

}  // namespace

std::size_t insert_spheres(State& s, const InsertRegion& region, const InsertRequest& req) {
  Random random(req.seed);
  const double r_max = req.radius * (1 + req.radius_spread);
  Occupancy occupancy(s, 2 * r_max);
  const Vec3 size = region.box.hi - region.box.lo;
  const double box_volume = size.prod();
  double solid = 0;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (region.box.contains(s.x[i])) solid += 4.0 / 3.0 * std::numbers::pi * std::pow(s.radius[i], 3);
  const std::size_t wanted = req.count > 0 ? req.count : std::size_t(-1);
  const std::size_t attempts = req.max_attempts > 0 ? req.max_attempts : 200 * std::max<std::size_t>(req.count, 1000);
  std::size_t added = 0;
  for (std::size_t a = 0; a < attempts && added < wanted; ++a) {
    const double r = req.radius * (1 + req.radius_spread * random.uniform(-1, 1));
    const Vec3 p(random.uniform(region.box.lo.x() + r, region.box.hi.x() - r),
                 random.uniform(region.box.lo.y() + r, region.box.hi.y() - r),
                 random.uniform(region.box.lo.z() + r, region.box.hi.z() - r));
    if (!admissible(region, s, p, r) || !occupancy.free_at(p, r)) continue;
    const double volume = 4.0 / 3.0 * std::numbers::pi * r * r * r;
    if ((solid + volume) / box_volume > req.max_solid_fraction) break;
    s.add_sphere(req.first_id + std::int64_t(added), p, r, req.density, req.material);
    occupancy.add(s.size() - 1);
    solid += volume;
    ++added;
  }
  return added;
}

std::size_t insert_clumps(State& s, const InsertRegion& region, const geometry::ClumpTemplate& clump, double scale,
                          std::size_t count, int material, double density, std::uint64_t seed, std::int64_t first_id) {
  Random random(seed);
  // Random sequential addition of the clumps' bounding spheres: a candidate whose bounding
  // sphere is clear of every sphere present (members included) overlaps nothing.
  const double r = scale * bounding_radius(clump);
  double cell = 2 * r;
  for (double ri : s.radius) cell = std::max(cell, r + ri);
  Occupancy occupancy(s, cell);
  const std::size_t attempts = 200 * std::max<std::size_t>(count, 1000);
  std::size_t added = 0;
  std::int64_t id = first_id;
  for (std::size_t a = 0; a < attempts && added < count; ++a) {
    const Vec3 p(random.uniform(region.box.lo.x() + r, region.box.hi.x() - r),
                 random.uniform(region.box.lo.y() + r, region.box.hi.y() - r),
                 random.uniform(region.box.lo.z() + r, region.box.hi.z() - r));
    if (!admissible(region, s, p, r) || !occupancy.free_at(p, r)) continue;
    // Uniform over rotations (Shoemake, "Uniform random rotations", Graphics Gems III, 1992).
    const double u1 = random.uniform(), u2 = 2 * std::numbers::pi * random.uniform(),
                 u3 = 2 * std::numbers::pi * random.uniform();
    const double a1 = std::sqrt(1 - u1), a2 = std::sqrt(u1);
    const Quat q(a1 * std::sin(u2), a1 * std::cos(u2), a2 * std::sin(u3), a2 * std::cos(u3));
    const std::size_t b = add_clump(s, clump, scale, id, p, q, density, material);
    for (std::int32_t k = s.bodies.member_start[b]; k < s.bodies.member_start[b + 1]; ++k)
      occupancy.add(std::size_t(s.bodies.member[std::size_t(k)]));
    id += std::int64_t(clump.spheres.size());
    ++added;
  }
  return added;
}

}  // namespace dem
