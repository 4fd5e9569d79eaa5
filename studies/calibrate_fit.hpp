#pragma once
// The fit of `diefill calibrate` (calibrate.hpp): each simulated result mapped over the two
// frictions, the frictions that meet the measurements, their confidence, and the outputs.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "studies/calibrate.hpp"

namespace studies {

struct DesignPoint {
  double sliding = 0, rolling = 0;
  std::uint64_t seed = 1;
};
struct Finished {
  DesignPoint point;
  TestResults results;
};

// One measured quantity against its map over the design, a quadratic in the two frictions:
// y = b0 + b1 μ + b2 μ_r + b3 μ μ_r + b4 μ² + b5 μ_r².
struct ObservableFit {
  std::string name, unit;
  double measured = 0, measured_error = 0;  // the lab's value and its standard error
  bool used = true;
  std::string left_out;                     // why, when not used
  double model_error = 0;                   // of the simulated value as a stand-in for the lab's (standard error)
  static constexpr int terms = 6;
  double coefficients[terms] = {};
  double scatter = 0;                       // of the tests about the map (one test's noise)
  double design_inverse[terms][terms] = {};  // (XᵀX)⁻¹ of the design: the map's own error at a point
  double fitted = 0;                        // the map at the calibrated frictions
  double residual = 0;                      // (fitted − measured) in combined standard errors
};

// A combination a μ + b μ_r of the two frictions (a² + b² = 1) and the 95 % half-width to which the
// measurements alone fix it (infinite: they do not fix it at all).
struct FrictionCombination {
  double sliding = 0, rolling = 0, ci = 0;
};

struct CalibrationFit {
  double sliding = 0, rolling = 0;
  double sliding_ci = 0, rolling_ci = 0;            // 95 % half-widths
  double sliding_data_ci = 0, rolling_data_ci = 0;  // the measurements' alone (infinite: they do not fix it)
  bool sliding_pinned = false, rolling_pinned = false;
  // The combination the measurements fix best and, across it, the one they fix worst: a heap's
  // angle and an orifice's flow both rise or fall with a weighted sum of the two frictions, so
  // that they fix that sum and leave the frictions' split to what else was measured
  // (docs/STUDIES.md, "calibration-round-trip").
  FrictionCombination best_fixed, least_fixed;
  bool inside_design = true;
  std::vector<ObservableFit> observables;
};

// A parameter counts as pinned when the measurements alone fix it to this (95 %).
inline constexpr double pinned_within = 0.05;

CalibrationFit fit_frictions(const std::vector<Finished>& tests, const MeasuredPowder& measured, const SimulatedTests& simulated);

// OUT/calibrated.toml (the [powder] keys and the [[materials]] entry, the confidence as
// comments), OUT/calibration.json and OUT/calibration_tests.csv; each written whole or not at all.
void write_calibration(const std::filesystem::path& out, const MeasuredPowder& measured, const SimulatedTests& simulated,
                       const std::vector<Finished>& tests, const CalibrationFit& fit);

}  // namespace studies
