#pragma once
// Insertion: a loose random packing of spheres or clumps (random sequential addition without
// overlaps) in a box, optionally restricted to the inside of a closed surface, reproducible from
// a seed.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>

#include "dem/model.hpp"
#include "dem/state.hpp"
#include "geometry/clump_template.hpp"

namespace dem {

struct InsertRegion {
  Box3 box;  // candidate centres are drawn here
  // When set, a centre is kept only if the sphere lies inside this solid (distance <= -r; the
  // field's solid-side band must reach the largest radius, or no grain deeper than it fits).
  std::shared_ptr<const geometry::WallField> inside;
  // ... and outside every wall of the model (distance >= r) when this is given.
  const Model* clear_of_walls = nullptr;
  // ... and where this accepts the centre and radius, when given.
  std::function<bool(const Vec3&, double)> accept;
};

struct InsertRequest {
  std::size_t count = 0;                 // spheres wanted (0: as many as fit)
  double radius = 5e-4;                  // [m] mean radius
  double radius_spread = 0.0;            // relative half-width of a uniform size distribution
  double max_solid_fraction = 0.35;      // stop when the region's box is this full
  int material = 0;
  double density = 2500;                 // [kg/m³]
  std::uint64_t seed = 1;
  std::int64_t first_id = 0;
  std::size_t max_attempts = 0;          // 0: 200 per sphere wanted
};

// Returns how many spheres were added; fewer than asked when the region is full.
std::size_t insert_spheres(State& state, const InsertRegion& region, const InsertRequest& request);

// Clumps of `clump` scaled by `scale`, centres drawn in region.box, uniformly random
// orientations, no overlap with each other or the grains present (their bounding spheres are
// tested, against the region too); members get ids from first_id on. Returns how many were
// added: fewer than `count` when the region is full.
std::size_t insert_clumps(State& state, const InsertRegion& region, const geometry::ClumpTemplate& clump, double scale,
                          std::size_t count, int material, double density, std::uint64_t seed,
                          std::int64_t first_id = 0);

// A small deterministic generator (SplitMix64): the same numbers on every platform.
class Random {
 public:
  explicit Random(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }  // [0, 1)
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

 private:
  std::uint64_t state_;
};

}  // namespace dem
