// The fit of `diefill calibrate` on maps known exactly: which combination of the two frictions
// the measurements fix, and to what (studies/calibrate_fit.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

#include "studies/calibrate.hpp"
#include "studies/calibrate_fit.hpp"

namespace {

using studies::Finished;
using studies::TestResults;

struct ExactMaps {
  std::function<double(double, double)> repose_deg, beverloo_c, solid_fraction;
};

// calibrate's design, three levels of each friction, each result exact (no scatter, so the maps
// carry no error of their own), and the lab's file measured at (μ, μ_r) with a 1° angle.
std::vector<Finished> design(const ExactMaps& maps) {
  std::vector<Finished> tests;
  for (const double mu : {0.2, 0.5, 0.8})
    for (const double mu_r : {0.0, 0.15, 0.3})
      tests.push_back({{mu, mu_r, 1}, TestResults{maps.repose_deg(mu, mu_r), maps.beverloo_c(mu, mu_r), maps.solid_fraction(mu, mu_r)}});
  return tests;
}

studies::MeasuredPowder measured_at(const ExactMaps& maps, double mu, double mu_r) {
  studies::MeasuredPowder m;
  m.particle_diameter = 1e-3;
  m.material_density = 7800;
  m.orifice_diameter = 12e-3;
  m.repose_deg = maps.repose_deg(mu, mu_r);
  m.repose_error_deg = 1;
  m.apparent_density = maps.solid_fraction(mu, mu_r) * m.material_density;
  m.flow_rate = maps.beverloo_c(mu, mu_r) * m.apparent_density * studies::beverloo_orifice(m.orifice_diameter, m.particle_diameter);
  return m;
}

}  // namespace

// Every measurement rises with the same sum μ + 2 μ_r: they fix that sum and nothing across it,
// however precise they are, and neither friction alone.
TEST(CalibrateFit, MeasurementsThatMoveWithOneSumFixOnlyThatSum) {
  const ExactMaps maps{[](double mu, double mu_r) { return 20 + 10 * (mu + 2 * mu_r); },
                       [](double mu, double mu_r) { return 1.0 - 0.1 * (mu + 2 * mu_r); },
                       [](double mu, double mu_r) { return 0.6 - 0.05 * (mu + 2 * mu_r); }};
  const studies::CalibrationFit fit = studies::fit_frictions(design(maps), measured_at(maps, 0.4, 0.12), studies::SimulatedTests{});
  EXPECT_NEAR(fit.best_fixed.sliding, 1 / std::sqrt(5.0), 1e-9);
  EXPECT_NEAR(fit.best_fixed.rolling, 2 / std::sqrt(5.0), 1e-9);
  EXPECT_TRUE(std::isfinite(fit.best_fixed.ci));
  EXPECT_NEAR(fit.least_fixed.sliding, 2 / std::sqrt(5.0), 1e-9);
  EXPECT_NEAR(fit.least_fixed.rolling, -1 / std::sqrt(5.0), 1e-9);
  EXPECT_FALSE(std::isfinite(fit.least_fixed.ci));
  EXPECT_FALSE(fit.sliding_pinned);
  EXPECT_FALSE(fit.rolling_pinned);
}

// The angle and the flow move with μ_r alone, the poured density with μ alone: the combinations
// are the frictions themselves, and μ is fixed by the density's repeatability, 1 % of it
// (ASTM B212), through its slope of -0.1 per unit μ: 1.96 · 0.01 · 0.56 / 0.1.
TEST(CalibrateFit, ADensityThatMovesWithSlidingFrictionAloneFixesItToItsRepeatability) {
  const ExactMaps maps{[](double, double mu_r) { return 20 + 30 * mu_r; }, [](double, double mu_r) { return 1.0 - 0.4 * mu_r; },
                       [](double mu, double) { return 0.6 - 0.1 * mu; }};
  const studies::CalibrationFit fit = studies::fit_frictions(design(maps), measured_at(maps, 0.4, 0.12), studies::SimulatedTests{});
  EXPECT_NEAR(fit.best_fixed.sliding, 0, 1e-9);
  EXPECT_NEAR(fit.best_fixed.rolling, 1, 1e-9);
  EXPECT_LT(fit.best_fixed.ci, 1.96 * 1 / 30.0);  // the angle's alone; the flow adds to it
  EXPECT_NEAR(fit.least_fixed.sliding, 1, 1e-9);
  EXPECT_NEAR(fit.least_fixed.rolling, 0, 1e-9);
  EXPECT_NEAR(fit.least_fixed.ci, 1.96 * 0.01 * 0.56 / 0.1, 1e-9);
  EXPECT_NEAR(fit.sliding_data_ci, fit.least_fixed.ci, 1e-9);
}
