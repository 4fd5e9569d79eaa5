#pragma once
// Counting every grain after the fill: in the cavity, in the shoe, elsewhere on the table, spilled
// over the table's edge (physical: the shoe sweeps powder aside), or lost (a fault: a grain thrown
// out through the domain's top, or missing from the final state); a grain through the die is a
// leak, refused. A clump counts once, by its centre of mass.
#include <string>
#include <vector>

#include "dem/model.hpp"
#include "dem/state.hpp"
#include "pipeline/plan.hpp"
#include "postprocess/field.hpp"

namespace pipeline {

struct Census {
  std::size_t inserted = 0;  // by the insertion, not by this count: the two are checked against each other
  std::size_t grains = 0, in_cavity = 0, in_shoe = 0, elsewhere = 0, spilled = 0, lost = 0, leaked = 0;
  dem::Vec3 leak = dem::Vec3::Zero();   // one leaked grain's centre
  std::vector<post::Grain> cavity;      // the cavity's grains as volumes for binning
  double grain_volume_m3 = 0;           // of every grain (a clump's true volume, not its spheres')
};

// What each member sphere of clump `body` counts for when the grains are binned: the members
// weighted so that they add up to the real grain's volume, counted once however much they overlap.
double member_weight(const dem::State& state, std::size_t body);

// `domain` is the simulated box: a grain frozen beyond its sides went over the table's edge.
Census count_grains(const dem::State& state, std::size_t inserted, double table_z, const ShoePlan& shoe,
                    const dem::Box3& domain);
// InputError naming the die when a grain left through it; a warning for grains lost to a fault,
// for grains spilled beside the shoe (counted in the report, not in the fill) and for a shoe that
// ran out of powder.
void check_losses(const Census& census, const std::string& die_source, const std::string& die_name);

}  // namespace pipeline
