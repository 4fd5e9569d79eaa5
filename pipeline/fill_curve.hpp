#pragma once
// The fill curve, the standard result of a die-filling study: the powder delivered into the
// cavity against time and the shoe's position (docs/INTERFACE.md, "fill_curve.csv").
#include <cstdint>
#include <filesystem>
#include <vector>

#include "dem/state.hpp"
#include "pipeline/plan.hpp"

namespace pipeline {

struct FillSample {
  double time = 0;            // [s]
  double shoe_x = 0;          // the shoe's centre along its path [m]
  std::int64_t grains = 0;    // in the cavity
  double mass = 0;            // of the powder below the table [kg]
};

// The grains in the cavity (the census's rule: a grain whose centre, a clump's centre of mass,
// lies below the table), and the mass of the powder below the table: of each grain, the part
// below the table's plane, as the density field bins it (so the curve ends at the report's
// fill.mass_kg, and a grain rattling at the surface of a full die moves it by a sliver, not by
// a whole grain). Collective on a split state: every rank gets the sums.
FillSample sample_fill(const dem::State& state, double table_z, double material_density, const ShoePlan& shoe);

// When the shoe's trailing inner wall passes the far edge of the die (x = die_far_x), the
// strike-off; the shoe's time of motion when it never does (a return stroke does).
double strike_off_time(const ShoePlan& shoe, double die_far_x);

// A seed ensemble's fill curve: per sample the seeds' means and the standard errors of them.
struct FillBand {
  std::vector<double> grains, grains_stderr, mass_stderr;
};

// `fill_curve.csv`: t_s, shoe_x_m, grains_in_cavity, mass_in_cavity_kg, fraction_of_capacity
// (the mass over the cavity's volume times the material density); with a band (an ensemble's
// mean curve), the mean grains and the standard errors grains_in_cavity_stderr,
// mass_in_cavity_kg_stderr and fraction_of_capacity_stderr besides.
void write_fill_curve(const std::vector<FillSample>& curve, double capacity_kg, const std::filesystem::path& csv,
                      const FillBand* band = nullptr);

}  // namespace pipeline
