#pragma once
// The grain-size extrapolation's mathematics (docs/PHYSICS.md §4.1): a weighted least-squares
// line through levels of the same scene at several grain diameters, its value and standard
// error at another diameter, and the tests that refuse a ladder outside the law's range.
#include <string>
#include <vector>

#include "mesh/feature_width.hpp"

namespace pipeline {

// One level: its grain diameter, its seeds' mean of a figure and that mean's standard error.
struct LevelValue {
  double diameter_m = 0;
  double value = 0;
  double stderr_ = 0;
};

struct AffineFit {
  double intercept = 0, slope = 0;     // value = intercept + slope × diameter
  double var_intercept = 0, var_slope = 0, covariance = 0;  // scaled by the Birge factor
  double chi2 = 0;                     // Σ ((value − line) / standard error)²
  int dof = 0;                         // levels − 2
  double birge = 1;                    // max(1, χ²/dof): the errors never below what the scatter shows
  double at(double diameter) const { return intercept + slope * diameter; }
  double stderr_at(double diameter) const;
};

// Weighted by 1/standard error²; three levels or more, of two diameters or more.
AffineFit fit_affine(const std::vector<LevelValue>& levels);

// The 99 % quantile of χ² with `dof` degrees of freedom (tabulated to 10, Wilson-Hilferty beyond).
double chi2_quantile_99(int dof);

// A level's seed noise scales as 1/√(grains in the cavity): the constant pooled over every
// level's seeds, each level's standard error from it. `spread` is each level's own standard error
// of its mean over `seeds`.
struct LevelSpread {
  int seeds = 0;
  double stderr_ = 0;
  double grains_in_cavity = 0;
};
std::vector<double> pooled_stderr(const std::vector<LevelSpread>& levels);

// Why a ladder cannot be extrapolated, or "" when it can.
// Before any run: more than a tenth of the cavity lies in features narrower than five grains of
// the coarsest level (there two wall layers meet and the fill is no longer affine in the
// diameter); `alpha_needed` is then the coarsest α that would do, for grains of `powder_diameter`.
struct Refusal {
  std::string reason;
  double alpha_needed = 0;
};
Refusal refuse_thin_features(const mesh::FeatureWidths& widths, double coarsest_diameter, double powder_diameter);
// After the runs: residuals beyond the seeds' noise (χ² above its 99 % quantile).
std::string refuse_curved(const AffineFit& fit);

inline constexpr double grains_across_needed = 5;   // docs/PHYSICS.md §4.1
inline constexpr double thin_share_allowed = 0.1;

}  // namespace pipeline
