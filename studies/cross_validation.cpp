// `diefill study cross-validation`: is a powder calibrated on its angle of repose right about its
// flow, and the reverse? One experiment gives both: a container drained through a slot (steady
// flow rate while it flows, outflow angle once it has stopped). The scene's powder, run with
// another seed, plays the measured powder; a sweep of rolling friction maps both results.
// Calibrated on the angle, the maps predict the flow; calibrated on the flow, the angle. Only
// rolling friction is fitted: one static angle can fix one parameter (the heap angle, which would
// fix a second, is not trustworthy yet), so sliding friction stays at the scene's value, as if
// measured on its own (a shear cell or a tilted plate).
#include <fmt/core.h>

#include <cmath>

#include "studies/studies.hpp"
#include "studies/study_scenes.hpp"
#include "core/log.hpp"

namespace studies {

namespace {

struct Point {
  double rolling = 0;
  double angle = 0, angle_error = 0;  // [°]
  double rate = 0, rate_error = 0;    // [kg/s]
};

Point drain(const Powder& base, const SlotContainer& c, double rolling, std::uint64_t seed, const std::string& label) {
  Powder p = base;
  p.spec.materials[std::size_t(p.powder)].rolling_friction = rolling;
  p.seed = seed;
  const SlotRun run = run_slot_container(p, c, label);
  const LineFit flow = steady_rate(run);
  const OutflowAngle angle = outflow_angle(run.state, c, p.diameter, 2 * p.diameter);
  diefill::log::info("{}: outflow {:.1f}° ± {:.1f}°, flow {:.2f} ± {:.2f} g/s", label, angle.angle_deg, angle.error_deg, flow.slope * 1e3,
                     flow.slope_error * 1e3);
  return {rolling, angle.angle_deg, angle.error_deg, flow.slope, flow.slope_error};
}

// A quantity against rolling friction: a line through the sweep, and the scatter of the runs
// about it (one run's noise: seed, packing).
struct Map {
  LineFit line;
  double scatter = 0;
  double at(double rolling) const { return line.intercept + line.slope * rolling; }
};

Map map_of(const std::vector<double>& rolling, const std::vector<double>& y) {
  Map m{fit_line(rolling, y), 0};
  double ss = 0;
  for (std::size_t i = 0; i < y.size(); ++i) ss += std::pow(y[i] - m.at(rolling[i]), 2);
  m.scatter = y.size() > 2 ? std::sqrt(ss / double(y.size() - 2)) : 0;
  return m;
}

// Calibration on one quantity through its map, and the other predicted from the calibrated
// friction through its own. Errors combine the observation's standard error with the maps'
// scatter, so that a prediction and an observation that differ by more than about two combined
// errors disagree.
struct Calibration {
  double rolling = 0, rolling_error = 0;
  double predicted = 0, predicted_error = 0, observed = 0, observed_error = 0;
};

Calibration calibrate(const Map& fitted, double observed, double observed_error, const Map& predicting, double other_observed,
                      double other_error) {
  Calibration c;
  c.rolling = (observed - fitted.line.intercept) / fitted.line.slope;
  c.rolling_error = std::hypot(observed_error, fitted.scatter) / std::abs(fitted.line.slope);
  c.predicted = predicting.at(c.rolling);
  c.predicted_error = std::hypot(predicting.scatter, predicting.line.slope * c.rolling_error);
  c.observed = other_observed;
  c.observed_error = other_error;
  return c;
}

// The sweep of rolling friction and the measured powder, drained alike.
struct Drains {
  double truth = 0;  // the measured powder's rolling friction
  std::vector<double> sweep;
  std::vector<Point> map;
  Point measured;
};

Drains run_drains(const Powder& powder, const SlotContainer& c, bool reduced) {
  Drains runs;
  runs.truth = powder.spec.materials[std::size_t(powder.powder)].rolling_friction;
  runs.sweep = reduced ? std::vector<double>{0.0, 0.1, 0.2, 0.3} : std::vector<double>{0.0, 0.05, 0.1, 0.15, 0.2, 0.3};
  for (double mu_r : runs.sweep)
    runs.map.push_back(drain(powder, c, mu_r, powder.seed, fmt::format("cross-validation: μ_r = {:.2f}", mu_r)));
  runs.measured = drain(powder, c, runs.truth, powder.seed + 1,
                        fmt::format("cross-validation: the measured powder (μ_r = {:.2f}, another seed)", runs.truth));
  return runs;
}

struct Calibrations {
  Map angle_map, rate_map;
  Calibration on_angle, on_rate;
};

Calibrations calibrate_both_ways(const Drains& runs) {
  std::vector<double> x, angles, rates;
  for (const Point& p : runs.map) x.push_back(p.rolling), angles.push_back(p.angle), rates.push_back(p.rate);
  const Point& measured = runs.measured;
  const Map angle_map = map_of(x, angles), rate_map = map_of(x, rates);
  const Calibration on_angle = calibrate(angle_map, measured.angle, measured.angle_error, rate_map, measured.rate, measured.rate_error);
  const Calibration on_rate = calibrate(rate_map, measured.rate, measured.rate_error, angle_map, measured.angle, measured.angle_error);
  diefill::log::info("cross-validation: from the angle μ_r = {:.3f} ± {:.3f}, flow predicted {:.2f} g/s for {:.2f}; from the flow "
                     "μ_r = {:.3f} ± {:.3f}, angle predicted {:.1f}° for {:.1f}° (true μ_r {:.2f})",
                     on_angle.rolling, on_angle.rolling_error, on_angle.predicted * 1e3, on_angle.observed * 1e3, on_rate.rolling,
                     on_rate.rolling_error, on_rate.predicted, on_rate.observed, runs.truth);
  return {angle_map, rate_map, on_angle, on_rate};
}

void write_drains_table(const Drains& runs, Output& out) {
  const Point& measured = runs.measured;
  std::vector<std::vector<nlohmann::json>> rows;
  for (const Point& p : runs.map) rows.push_back({"map", p.rolling, p.angle, p.angle_error, p.rate, p.rate_error});
  rows.push_back({"measured", measured.rolling, measured.angle, measured.angle_error, measured.rate, measured.rate_error});
  out.table("cross_validation.csv", {"run", "rolling_friction", "outflow_angle_deg", "outflow_error_deg", "rate_kg_s", "rate_error_kg_s"},
            rows);
}

void chart_map(const Drains& runs, const std::string& file, const std::string& title, const std::string& y_label, double scale,
               bool angle, const Map& line, const Calibration& fitted_here, Output& out) {
  const Point& measured = runs.measured;
  Chart ch{file, title, "rolling friction μ_r", y_label};
  Series points{"sweep (DEM)", {}, {}, {}, "points"}, fit{"map (line fit)", {}, {}, {}, "line"};
  for (const Point& p : runs.map)
    points.x.push_back(p.rolling), points.y.push_back(scale * (angle ? p.angle : p.rate)),
        points.error.push_back(scale * (angle ? p.angle_error : p.rate_error));
  for (double mu_r : {runs.sweep.front(), runs.sweep.back()}) fit.x.push_back(mu_r), fit.y.push_back(scale * line.at(mu_r));
  const double observed = angle ? measured.angle : measured.rate, error = angle ? measured.angle_error : measured.rate_error;
  Series measured_series{"the measured powder", {runs.truth}, {scale * observed}, {scale * error}, "points"};
  Series calibrated{"calibrated on this", {fitted_here.rolling}, {scale * observed}, {}, "points"};
  ch.series = {points, fit, measured_series, calibrated};
  out.chart(ch);
}

nlohmann::json calibration_json(const Calibration& cal, const char* predicted_name, double relative_scale) {
  return nlohmann::json{{"rolling_friction", cal.rolling},
                        {"rolling_friction_error", cal.rolling_error},
                        {predicted_name, {{"predicted", cal.predicted}, {"predicted_error", cal.predicted_error},
                                          {"observed", cal.observed}, {"observed_error", cal.observed_error},
                                          {"error", (cal.predicted - cal.observed) * relative_scale}}}};
}

nlohmann::json cross_validation_results(const Powder& powder, const SlotContainer& c, const Drains& runs, const Calibrations& cal) {
  const Point& measured = runs.measured;
  const Map& angle_map = cal.angle_map;
  const Map& rate_map = cal.rate_map;
  return {
      {"grain_diameter_m", powder.diameter},
      {"sliding_friction", powder.spec.materials[std::size_t(powder.powder)].sliding_friction},
      {"true_rolling_friction", runs.truth},
      {"container", {{"slot_width_m", c.slot_width}, {"length_m", c.length}, {"width_m", c.width}, {"fill_height_m", c.fill_height}}},
      {"maps",
       {{"angle_deg", {{"intercept", angle_map.line.intercept}, {"slope", angle_map.line.slope},
                       {"slope_error", angle_map.line.slope_error}, {"scatter", angle_map.scatter}}},
        {"rate_kg_s", {{"intercept", rate_map.line.intercept}, {"slope", rate_map.line.slope},
                       {"slope_error", rate_map.line.slope_error}, {"scatter", rate_map.scatter}}}}},
      {"measured", {{"angle_deg", measured.angle}, {"angle_error_deg", measured.angle_error}, {"rate_kg_s", measured.rate},
                    {"rate_error_kg_s", measured.rate_error}}},
      // Errors: the flow's relative, the angle's in degrees.
      {"calibrated_on_angle", calibration_json(cal.on_angle, "rate_kg_s", 1 / cal.on_angle.observed)},
      {"calibrated_on_flow", calibration_json(cal.on_rate, "angle_deg", 1.0)}};
}

}  // namespace

void cross_validation(const scene::PipelineScene& scene, bool reduced, Output& out) {
  const Powder powder = powder_of(scene);
  const SlotContainer c = outflow_container(powder.diameter, reduced);
  const Drains runs = run_drains(powder, c, reduced);
  const Calibrations cal = calibrate_both_ways(runs);
  write_drains_table(runs, out);
  chart_map(runs, "cross_validation_angle.png", "Outflow angle against rolling friction", "outflow angle [°]", 1, true, cal.angle_map,
            cal.on_angle, out);
  chart_map(runs, "cross_validation_flow.png", "Slot flow rate against rolling friction", "flow rate [g/s]", 1e3, false, cal.rate_map,
            cal.on_rate, out);
  out.results = cross_validation_results(powder, c, runs, cal);
}

}  // namespace studies
