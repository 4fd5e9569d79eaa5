#include "pipeline/extrapolate.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace pipeline {

double AffineFit::stderr_at(double d) const {
  return std::sqrt(std::max(0.0, var_intercept + 2 * d * covariance + d * d * var_slope));
}

AffineFit fit_affine(const std::vector<LevelValue>& levels) {
  if (levels.size() < 3) throw std::invalid_argument("an affine fit with an error needs three levels or more");
  double s = 0, sx = 0, sxx = 0, sy = 0, sxy = 0;
  for (const LevelValue& l : levels) {
    if (!(l.stderr_ > 0)) throw std::invalid_argument("a level without a standard error: its seeds gave one value");
    const double w = 1 / (l.stderr_ * l.stderr_);
    s += w, sx += w * l.diameter_m, sxx += w * l.diameter_m * l.diameter_m, sy += w * l.value, sxy += w * l.diameter_m * l.value;
  }
  const double delta = s * sxx - sx * sx;
  if (!(delta > 0)) throw std::invalid_argument("an affine fit needs two diameters or more");
  AffineFit f;
  f.intercept = (sxx * sy - sx * sxy) / delta;
  f.slope = (s * sxy - sx * sy) / delta;
  for (const LevelValue& l : levels) f.chi2 += std::pow((l.value - f.at(l.diameter_m)) / l.stderr_, 2);
  f.dof = int(levels.size()) - 2;
  f.birge = std::max(1.0, f.chi2 / f.dof);
  f.var_intercept = f.birge * sxx / delta;
  f.var_slope = f.birge * s / delta;
  f.covariance = -f.birge * sx / delta;
  return f;
}

double chi2_quantile_99(int dof) {
  static const double table[] = {6.635, 9.210, 11.345, 13.277, 15.086, 16.812, 18.475, 20.090, 21.666, 23.209};
  if (dof < 1) throw std::invalid_argument("χ² needs a degree of freedom");
  if (dof <= 10) return table[dof - 1];
  const double k = dof, z = 2.3263;  // the normal's 99 % quantile
  return k * std::pow(1 - 2 / (9 * k) + z * std::sqrt(2 / (9 * k)), 3);
}

std::vector<double> pooled_stderr(const std::vector<LevelSpread>& levels) {
  double squares = 0, dof = 0;
  for (const LevelSpread& l : levels) {
    // (n − 1) s² = (n − 1) n se² of the level's seeds, in units of one grain in the cavity.
    squares += double(l.seeds - 1) * double(l.seeds) * l.stderr_ * l.stderr_ * l.grains_in_cavity;
    dof += double(l.seeds - 1);
  }
  if (!(dof > 0)) throw std::invalid_argument("pooled errors need two seeds of a level or more");
  if (!(squares > 0)) throw std::invalid_argument("no level's seeds differ: no noise to pool");
  std::vector<double> out;
  for (const LevelSpread& l : levels) out.push_back(std::sqrt(squares / dof / (l.grains_in_cavity * double(l.seeds))));
  return out;
}

Refusal refuse_thin_features(const mesh::FeatureWidths& widths, double coarsest_diameter, double powder_diameter) {
  const double limit = grains_across_needed * coarsest_diameter;
  const double share = widths.share_below(limit);
  if (share <= thin_share_allowed) return {};
  // The width below which a tenth of the cavity lies: features that wide must hold five grains.
  std::vector<mesh::FeatureWidths::Crossing> sorted = widths.crossings;
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.width < b.width; });
  double volume = 0, width = sorted.front().width;
  for (const auto& c : sorted) {
    width = c.width;
    if ((volume += c.volume) > thin_share_allowed * widths.cavity_volume) break;
  }
  const double alpha = width / (grains_across_needed * powder_diameter);
  const double digits = std::pow(10.0, std::floor(std::log10(alpha)) - 1);  // two significant figures, rounded down
  Refusal r;
  r.alpha_needed = std::floor(alpha / digits) * digits;
  const auto* narrow = widths.narrowest();
  r.reason = fmt::format("{:.0f} % of the cavity lies in parts narrower than {} grains of the coarsest level ({:.3g} mm: "
                         "{:.3g} mm grains), such as the part {:.3g} mm wide between ({:.3g}, {:.3g}, {:.3g}) and "
                         "({:.3g}, {:.3g}, {:.3g}) mm, where the wall layers meet and the fill is no longer affine in the "
                         "grain size (docs/PHYSICS.md §4.1); a coarsest α of {:.2g} or less would do",
                         100 * share, grains_across_needed, limit * 1e3, coarsest_diameter * 1e3, narrow->width * 1e3,
                         narrow->a.x() * 1e3, narrow->a.y() * 1e3, narrow->a.z() * 1e3, narrow->b.x() * 1e3, narrow->b.y() * 1e3,
                         narrow->b.z() * 1e3, r.alpha_needed);
  return r;
}

std::string refuse_curved(const AffineFit& fit) {
  const double limit = chi2_quantile_99(fit.dof);
  if (fit.chi2 <= limit) return "";
  return fmt::format("the levels lie off a line beyond their seeds' noise (χ² {:.3g} with {} degree(s) of freedom, over its "
                     "99 % quantile {:.3g}): they are not in the range where the fill is affine in the grain size",
                     fit.chi2, fit.dof, limit);
}

}  // namespace pipeline
