#include "pipeline/census.hpp"

#include <fmt/core.h>

#include <cmath>
#include <numbers>

#include "core/error.hpp"
#include "core/log.hpp"

namespace pipeline {

using dem::Vec3;

namespace {

// A grain once: a free sphere, or a clump by its centre of mass.
struct GrainRef {
  Vec3 centre;
  bool active;
  std::int64_t body;  // -1: the free sphere `index`
  std::size_t index;
};

std::vector<GrainRef> grains_of(const dem::State& s) {
  std::vector<GrainRef> grains;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.body[i] < 0) grains.push_back({s.x[i], s.active[i] != 0, -1, i});
  for (std::size_t b = 0; b < s.bodies.size(); ++b) grains.push_back({s.bodies.x[b], s.bodies.active[b] != 0, std::int64_t(b), b});
  return grains;
}

// The grain's volume as spheres for binning (member_weight).
void add_volume(const dem::State& s, const GrainRef& g, std::vector<post::Grain>& out) {
  if (g.body < 0) {
    out.push_back({s.x[g.index], s.radius[g.index], 1.0});
    return;
  }
  const dem::Bodies& b = s.bodies;
  const double weight = member_weight(s, g.index);
  for (std::int32_t m = b.member_start[g.index]; m < b.member_start[g.index + 1]; ++m) {
    const std::size_t i = std::size_t(b.member[std::size_t(m)]);
    out.push_back({s.x[i], s.radius[i], weight});
  }
}

}  // namespace

double member_weight(const dem::State& s, std::size_t body) {
  const dem::Bodies& b = s.bodies;
  double members = 0;
  for (std::int32_t m = b.member_start[body]; m < b.member_start[body + 1]; ++m)
    members += 4.0 / 3.0 * std::numbers::pi * std::pow(s.radius[std::size_t(b.member[std::size_t(m)])], 3);
  return b.volume[body] / members;
}

Census count_grains(const dem::State& state, std::size_t inserted, double table_z, const ShoePlan& shoe,
                    const dem::Box3& domain) {
  Census c;
  c.inserted = inserted;
  const Vec3 shoe_centre = shoe.motion.position(state.time);
  std::vector<post::Grain> all;
  for (const GrainRef& g : grains_of(state)) {
    ++c.grains;
    add_volume(state, g, all);
    // A grain is frozen at the first neighbour build after it left the domain (docs/PHYSICS.md),
    // within half a skin of the face it crossed: below the table it went through the die (a
    // leak); beyond the sides, over the table's edge beside the shoe (spilled, harmless to the
    // fill); through the top it was thrown out, which only a fault does (lost).
    if (!g.active) {
      const bool beside = (g.centre.head<2>().array() < domain.lo.head<2>().array()).any() ||
                          (g.centre.head<2>().array() > domain.hi.head<2>().array()).any();
      if (g.centre.z() < table_z) c.leak = g.centre, ++c.leaked;
      else if (beside) ++c.spilled;
      else ++c.lost;
    } else if (g.centre.z() < table_z) {
      ++c.in_cavity;
      add_volume(state, g, c.cavity);
    } else if (std::abs(g.centre.x() - shoe_centre.x()) < 0.5 * shoe.length &&
               std::abs(g.centre.y() - shoe_centre.y()) < 0.5 * shoe.width) {
      ++c.in_shoe;
    } else {
      ++c.elsewhere;
    }
  }
  // A grain the final state no longer holds is lost too (a fault of the exchange or the gather).
  if (c.inserted > c.grains) c.lost += c.inserted - c.grains;
  // Summed from the same weighted members the density binning gets, so that the report shows the
  // volume the field holds.
  for (const post::Grain& g : all) c.grain_volume_m3 += g.weight * 4.0 / 3.0 * std::numbers::pi * std::pow(g.radius, 3);
  return c;
}

void check_losses(const Census& c, const std::string& die_source, const std::string& die_name) {
  if (c.leaked > 0)
    throw diefill::InputError(die_source, "particles.leaked",
                              fmt::format("{} grains left the simulated domain below the die table, through the die (one at "
                                          "({:.3g}, {:.3g}, {:.3g}) mm)",
                                          c.leaked, c.leak.x() * 1e3, c.leak.y() * 1e3, c.leak.z() * 1e3),
                              "Check the die mesh for holes or walls thinner than its voxels");
  if (c.grains != c.inserted || c.lost > 0)
    diefill::log::warn("{}: {} grains lost to a fault (thrown out through the simulated domain's top, or missing: {} "
                       "inserted, {} in the final state); report.json's stability.checks_passed is false",
                       die_name, c.lost, c.inserted, c.grains);
  if (c.spilled > 0)
    diefill::log::info("{}: {} grains spilled over the die table's edge beside the shoe; counted in report.json "
                       "(particles.spilled), not in the fill",
                       die_name, c.spilled);
  // A shoe that ends (nearly) empty may have run out before the cavity was full: a die larger
  // than the shoe's powder (the shared 304 mm flange disc under a 3000-grain shoe) is no fill.
  if (c.in_shoe * 20 < c.grains)
    diefill::log::warn("{}: the shoe ran out of powder ({} of its {} grains left in it, {} in the cavity): the cavity may "
                       "not be full. Give the shoe more powder (shoe.fill_height, shoe.length, powder.max_grains)",
                       die_name, c.in_shoe, c.grains, c.in_cavity);
}

}  // namespace pipeline
