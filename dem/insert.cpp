#include "dem/insert.hpp"

#include <cmath>
#include <numbers>
#include <unordered_map>

#include "dem/walls.hpp"

namespace dem {

std::size_t insert_spheres(State& s, const InsertRegion& region, const InsertRequest& req) {
  Random random(req.seed);
  const double r_max = req.radius * (1 + req.radius_spread);
  const double cell = 2 * r_max;
  // Spatial hash of every sphere already present, to reject overlaps.
  std::unordered_map<std::uint64_t, std::vector<std::int32_t>> grid;
  auto key = [&](const Vec3& p) {
    const auto c = (p / cell).array().floor().cast<std::int64_t>();
    return (std::uint64_t(c.x() & 0x1FFFFF) << 42) | (std::uint64_t(c.y() & 0x1FFFFF) << 21) | std::uint64_t(c.z() & 0x1FFFFF);
  };
  for (std::size_t i = 0; i < s.size(); ++i) grid[key(s.x[i])].push_back(std::int32_t(i));
  auto free_at = [&](const Vec3& p, double r) {
    const auto c = (p / cell).array().floor().cast<std::int64_t>();
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const Vec3 q = (Vec3(double(c.x() + dx), double(c.y() + dy), double(c.z() + dz)) + Vec3::Constant(0.5)) * cell;
          auto it = grid.find(key(q));
          if (it == grid.end()) continue;
          for (std::int32_t j : it->second) {
            const double reach = r + s.radius[std::size_t(j)];
            if ((s.x[std::size_t(j)] - p).squaredNorm() < reach * reach) return false;
          }
        }
    return true;
  };
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
    if (region.accept && !region.accept(p, r)) continue;
    if (region.inside && region.inside->signed_distance(p) > -r) continue;
    if (region.clear_of_walls && wall_distance(*region.clear_of_walls, s.time, p) < r) continue;
    if (!free_at(p, r)) continue;
    const double volume = 4.0 / 3.0 * std::numbers::pi * r * r * r;
    if ((solid + volume) / box_volume > req.max_solid_fraction) break;
    s.add_sphere(req.first_id + std::int64_t(added), p, r, req.density, req.material);
    grid[key(p)].push_back(std::int32_t(s.size() - 1));
    solid += volume;
    ++added;
  }
  return added;
}

}  // namespace dem
