#include "studies/calibrate_fit.hpp"

#include <fmt/core.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>
#include <utility>
#include <nlohmann/json.hpp>

#include "core/atomic_file.hpp"
#include "core/log.hpp"

namespace studies {

namespace {

using Vector2 = Eigen::Vector2d;
using Matrix2 = Eigen::Matrix2d;

// Without a measurement that fixes a friction, the fit keeps it near the design's centre, no
// farther than the design reaches: a weak prior, the design's centre and half-widths, so that
// an unpinned friction comes out finite and is said to be unpinned.
const Vector2 prior_centre(0.5, 0.15), prior_width(0.3, 0.15);
// The apparent density's repeatability (ASTM B212: about 1 %).
constexpr double apparent_density_error = 0.01;

using Terms = Eigen::Matrix<double, ObservableFit::terms, 1>;

// The map's terms at p: 1, μ, μ_r, μ μ_r, μ², μ_r².
Terms terms_at(const Vector2& p) {
  Terms x;
  x << 1, p[0], p[1], p[0] * p[1], p[0] * p[0], p[1] * p[1];
  return x;
}

double map_at(const ObservableFit& o, const Vector2& p) { return Eigen::Map<const Terms>(o.coefficients).dot(terms_at(p)); }
Eigen::RowVector2d map_gradient(const ObservableFit& o, const Vector2& p) {
  const double* b = o.coefficients;
  return {b[1] + b[3] * p[1] + 2 * b[4] * p[0], b[2] + b[3] * p[0] + 2 * b[5] * p[1]};
}

void fit_map(ObservableFit& o, const std::vector<Finished>& tests, double TestResults::*member) {
  constexpr int n_terms = ObservableFit::terms;
  Eigen::MatrixXd x(Eigen::Index(tests.size()), n_terms);
  Eigen::VectorXd y(Eigen::Index(tests.size()));
  for (std::size_t i = 0; i < tests.size(); ++i) {
    x.row(Eigen::Index(i)) = terms_at(Vector2(tests[i].point.sliding, tests[i].point.rolling)).transpose();
    y[Eigen::Index(i)] = tests[i].results.*member;
  }
  const Terms b = x.colPivHouseholderQr().solve(y);
  const Eigen::Matrix<double, n_terms, n_terms> inverse = (x.transpose() * x).inverse();
  for (int k = 0; k < n_terms; ++k) {
    o.coefficients[k] = b[k];
    for (int l = 0; l < n_terms; ++l) o.design_inverse[k][l] = inverse(k, l);
  }
  const double dof = double(tests.size()) - n_terms;
  // Row by row: GCC 12 takes Eigen's freeing of the temporary x b - y for a use after free
  // (-Wuse-after-free, a false positive; warnings are errors).
  double squared = 0;
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    const double residual = x.row(i).dot(b) - y[i];
    squared += residual * residual;
  }
  o.scatter = dof > 0 ? std::sqrt(squared / dof) : 0;
}

ObservableFit observable(std::string name, std::string unit, double measured, double measured_error) {
  ObservableFit o;
  o.name = std::move(name);
  o.unit = std::move(unit);
  o.measured = measured;
  o.measured_error = measured_error;
  return o;
}

// The three quantities, each with the lab's value and its error; the solid fraction only where
// spheres reach it (irregular grains pack looser than any friction makes spheres pack).
std::vector<ObservableFit> observables(const std::vector<Finished>& tests, const MeasuredPowder& m, const SimulatedTests& simulated) {
  ObservableFit repose = observable("repose angle", "°", m.repose_deg, m.repose_error_deg);
  fit_map(repose, tests, &TestResults::repose_deg);
  const double c = m.flow_rate / (m.apparent_density * beverloo_orifice(m.orifice_diameter, m.particle_diameter));
  ObservableFit flow = observable("Beverloo C of the orifice flow", "", c, c * std::hypot(m.flow_rate_error, apparent_density_error));
  fit_map(flow, tests, &TestResults::beverloo_c);
  // C of the simulated orifice moves with k as (D − k d)^{-5/2}: k's uncertainty is the map's
  // error as a stand-in for the lab's C (calibrate.hpp).
  flow.model_error = c * 2.5 * beverloo_k_error / (simulated.orifice_grains - beverloo_k);
  const double phi = m.solid_fraction();
  ObservableFit packing = observable("poured solid fraction", "", phi, phi * apparent_density_error);
  fit_map(packing, tests, &TestResults::solid_fraction);
  const auto [lo, hi] = std::minmax_element(tests.begin(), tests.end(), [](const Finished& a, const Finished& b) {
    return a.results.solid_fraction < b.results.solid_fraction;
  });
  constexpr double reach = 0.02;
  if (phi < lo->results.solid_fraction - reach || phi > hi->results.solid_fraction + reach) {
    packing.used = false;
    packing.left_out = fmt::format("the spheres' poured solid fraction spans {:.3f}-{:.3f} over the design, the powder's is {:.3f} "
                                   "(irregular grains pack looser than spheres): left out of the fit",
                                   lo->results.solid_fraction, hi->results.solid_fraction, phi);
  }
  return {repose, flow, packing};
}

// The map's own variance at p: the tests' scatter through the design (falls with more seeds).
double map_variance(const ObservableFit& o, const Vector2& p) {
  const Terms x = terms_at(p);
  double v = 0;
  for (int k = 0; k < ObservableFit::terms; ++k)
    for (int l = 0; l < ObservableFit::terms; ++l) v += x[k] * o.design_inverse[k][l] * x[l];
  return o.scatter * o.scatter * v;
}

// The combined standard error of measured against mapped, squared, inverted.
double weight(const ObservableFit& o, const Vector2& p) {
  return 1 / (o.measured_error * o.measured_error + o.model_error * o.model_error + map_variance(o, p));
}

// The measurements' information about the frictions at p (Gauss-Newton's JᵀWJ).
Matrix2 information(const std::vector<ObservableFit>& obs, const Vector2& p) {
  Matrix2 h = Matrix2::Zero();
  for (const ObservableFit& o : obs)
    if (o.used) h += weight(o, p) * map_gradient(o, p).transpose() * map_gradient(o, p);
  return h;
}

// Least squares of the maps against the measurements with the weak prior, by Gauss-Newton
// (the maps' cross term makes it slightly nonlinear); frictions kept non-negative.
Vector2 best_frictions(const std::vector<ObservableFit>& obs) {
  const Matrix2 prior = prior_width.cwiseInverse().cwiseAbs2().asDiagonal();
  Vector2 p = prior_centre;
  for (int iteration = 0; iteration < 50; ++iteration) {
    Vector2 gradient = prior * (p - prior_centre);
    for (const ObservableFit& o : obs)
      if (o.used) gradient += weight(o, p) * map_gradient(o, p).transpose() * (map_at(o, p) - o.measured);
    const Vector2 next = (p - (information(obs, p) + prior).ldlt().solve(gradient)).cwiseMax(0.0);
    const bool settled = (next - p).norm() < 1e-9;
    p = next;
    if (settled) break;
  }
  return p;
}

// The combinations of the frictions the measurements fix best and worst: the eigenvectors of
// their information, each 95 % half-width 1.96 / √(its eigenvalue); written with the larger of
// the two weights positive.
std::pair<FrictionCombination, FrictionCombination> fixed_combinations(const Matrix2& data) {
  const Eigen::SelfAdjointEigenSolver<Matrix2> eigen(data);  // eigenvalues ascending
  const double largest = eigen.eigenvalues()[1];
  const auto combination = [&](int k) {
    Vector2 weights = eigen.eigenvectors().col(k);
    if (weights[std::abs(weights[0]) >= std::abs(weights[1]) ? 0 : 1] < 0) weights = -weights;
    const double lambda = eigen.eigenvalues()[k];
    const bool fixed = lambda > 0 && lambda > 1e-12 * largest;
    return FrictionCombination{weights[0], weights[1], fixed ? 1.96 / std::sqrt(lambda) : std::numeric_limits<double>::infinity()};
  };
  return {combination(1), combination(0)};
}

}  // namespace

CalibrationFit fit_frictions(const std::vector<Finished>& tests, const MeasuredPowder& measured, const SimulatedTests& simulated) {
  CalibrationFit fit;
  fit.observables = observables(tests, measured, simulated);
  const Vector2 p = best_frictions(fit.observables);
  fit.sliding = p[0];
  fit.rolling = p[1];
  const Matrix2 data = information(fit.observables, p);
  const Matrix2 with_prior = data + Matrix2(prior_width.cwiseInverse().cwiseAbs2().asDiagonal());
  const Vector2 ci = 1.96 * with_prior.inverse().diagonal().cwiseSqrt();
  fit.sliding_ci = ci[0];
  fit.rolling_ci = ci[1];
  // The measurements alone: where they leave a combination unfixed, neither friction is fixed.
  std::tie(fit.best_fixed, fit.least_fixed) = fixed_combinations(data);
  const Vector2 data_ci = std::isfinite(fit.least_fixed.ci) ? Vector2(1.96 * data.inverse().diagonal().cwiseSqrt())
                                                            : Vector2::Constant(std::numeric_limits<double>::infinity());
  fit.sliding_data_ci = data_ci[0];
  fit.rolling_data_ci = data_ci[1];
  fit.sliding_pinned = data_ci[0] <= pinned_within;
  fit.rolling_pinned = data_ci[1] <= pinned_within;
  const auto within = [&](double x, double DesignPoint::*along) {
    const auto [lo, hi] = std::minmax_element(tests.begin(), tests.end(),
                                              [&](const Finished& a, const Finished& b) { return a.point.*along < b.point.*along; });
    return x >= lo->point.*along && x <= hi->point.*along;
  };
  fit.inside_design = within(p[0], &DesignPoint::sliding) && within(p[1], &DesignPoint::rolling);
  for (ObservableFit& o : fit.observables) {
    o.fitted = map_at(o, p);
    o.residual = (o.fitted - o.measured) * std::sqrt(weight(o, p));
  }
  return fit;
}

namespace {

std::string confidence_line(const char* name, double value, double ci, double data_ci, bool pinned) {
  if (pinned) return fmt::format("# {} = {:.3f} ± {:.3f} (95 %): pinned by the measurements\n", name, value, ci);
  return fmt::format("# {} = {:.3f} ± {:.3f} (95 %): NOT pinned by these measurements (alone they fix it to ± {:.3g}; ± {} "
                     "needed): measure it on its own or add a test that moves with it\n",
                     name, value, ci, data_ci, pinned_within);
}

std::string combination_text(const FrictionCombination& c) {
  return fmt::format("{:.2f} μ {} {:.2f} μ_r", c.sliding, c.rolling < 0 ? "-" : "+", std::abs(c.rolling));
}
std::string fixed_text(const FrictionCombination& c) {
  return std::isfinite(c.ci) ? fmt::format("fix {} to ± {:.3g}", combination_text(c), c.ci) : fmt::format("leave {} unfixed", combination_text(c));
}

std::string calibrated_toml(const MeasuredPowder& m, const CalibrationFit& fit) {
  std::string out = fmt::format("# diefill calibrate {}: the powder for a scene (docs/INTERFACE.md, \"Your powder\").\n", m.source);
  out += confidence_line("sliding_friction", fit.sliding, fit.sliding_ci, fit.sliding_data_ci, fit.sliding_pinned);
  out += confidence_line("rolling_friction", fit.rolling, fit.rolling_ci, fit.rolling_data_ci, fit.rolling_pinned);
  out += fmt::format("# the measurements alone {} and {} (95 %)\n", fixed_text(fit.best_fixed), fixed_text(fit.least_fixed));
  if (!fit.inside_design) out += "# outside the tested design (μ 0.2-0.8, μ_r 0-0.3): extrapolated by the maps\n";
  for (const ObservableFit& o : fit.observables)
    out += o.used ? fmt::format("# {}: measured {:.4g}, fitted {:.4g} ({:+.2f} standard errors)\n", o.name, o.measured, o.fitted, o.residual)
                  : fmt::format("# {}: {}\n", o.name, o.left_out);
  out += fmt::format("\n[powder]\nparticle_diameter = {:.6g}\ndiameter_spread = {:.6g}\n\n", m.particle_diameter, m.diameter_spread);
  out += fmt::format("[[materials]]\nname = \"powder\"\ndensity = {:.6g}\nsliding_friction = {:.3f}\nrolling_friction = {:.3f}\n",
                     m.material_density, fit.sliding, fit.rolling);
  return out;
}

nlohmann::json fit_json(const CalibrationFit& fit) {
  nlohmann::json observables = nlohmann::json::array();
  for (const ObservableFit& o : fit.observables)
    observables.push_back({{"name", o.name}, {"measured", o.measured}, {"measured_error", o.measured_error}, {"used", o.used},
                           {"left_out", o.left_out}, {"model_error", o.model_error}, {"map", o.coefficients}, {"scatter", o.scatter}, {"fitted", o.fitted},
                           {"residual", o.residual}});
  const auto finite_or_null = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  const auto combination_json = [&](const FrictionCombination& c) {
    return nlohmann::json{{"sliding_weight", c.sliding}, {"rolling_weight", c.rolling}, {"measurements_ci95", finite_or_null(c.ci)}};
  };
  return {{"sliding_friction", {{"value", fit.sliding}, {"ci95", fit.sliding_ci}, {"measurements_ci95", finite_or_null(fit.sliding_data_ci)},
                                {"pinned", fit.sliding_pinned}}},
          {"rolling_friction", {{"value", fit.rolling}, {"ci95", fit.rolling_ci}, {"measurements_ci95", finite_or_null(fit.rolling_data_ci)},
                                {"pinned", fit.rolling_pinned}}},
          {"pinned_within", pinned_within},
          {"fixed_combinations", nlohmann::json::array({combination_json(fit.best_fixed), combination_json(fit.least_fixed)})},
          {"inside_design", fit.inside_design},
          {"observables", observables}};
}

}  // namespace

void write_calibration(const std::filesystem::path& out, const MeasuredPowder& m, const SimulatedTests& simulated,
                       const std::vector<Finished>& tests, const CalibrationFit& fit) {
  std::string csv = "sliding_friction,rolling_friction,seed,repose_deg,beverloo_c,solid_fraction\n";
  nlohmann::json rows = nlohmann::json::array();
  for (const Finished& t : tests) {
    csv += fmt::format("{},{},{},{:.6g},{:.6g},{:.6g}\n", t.point.sliding, t.point.rolling, t.point.seed, t.results.repose_deg,
                       t.results.beverloo_c, t.results.solid_fraction);
    rows.push_back({{"sliding_friction", t.point.sliding}, {"rolling_friction", t.point.rolling}, {"seed", t.point.seed},
                    {"repose_deg", t.results.repose_deg}, {"beverloo_c", t.results.beverloo_c},
                    {"solid_fraction", t.results.solid_fraction}});
  }
  nlohmann::json results = fit_json(fit);
  results["measured"] = m.source;
  results["simulated_diameter_m"] = simulated.powder.diameter;
  results["orifice_grains"] = simulated.orifice_grains;
  results["beverloo_k"] = beverloo_k;
  results["tests"] = rows;
  diefill::write_file_atomic(out / "calibration_tests.csv", csv);
  diefill::write_file_atomic(out / "calibration.json", results.dump(2) + "\n");
  diefill::write_file_atomic(out / "calibrated.toml", calibrated_toml(m, fit));
  diefill::log::info("calibrate: μ = {:.3f} ± {:.3f}{}, μ_r = {:.3f} ± {:.3f}{} (95 %)", fit.sliding, fit.sliding_ci,
                     fit.sliding_pinned ? "" : " (not pinned)", fit.rolling, fit.rolling_ci, fit.rolling_pinned ? "" : " (not pinned)");
}

}  // namespace studies
