// `diefill study calibration-round-trip`: how well `diefill calibrate` recovers frictions it
// knows. A twin powder (μ = 0.4, μ_r = 0.12: inside the design, off its points) is measured by the
// same tests at another grain size (the orifice 8 grains wide instead of 6) and other seeds, as a
// lab would measure it: each test repeated, its mean and standard error written as the lab's
// file; then calibrated back with as many seeds a design point.
#include <fmt/core.h>

#include <fstream>

#include "core/atomic_file.hpp"
#include "studies/calibrate.hpp"
#include "studies/studies.hpp"

namespace studies {

namespace {

// The lab's powder: grains of `diameter` through an orifice 12 of them wide under the Hall
// funnel's 60° cone, simulated with spheres twice as large, six across the orifice (the twin's
// eight across).
MeasuredPowder lab_powder(double diameter) {
  MeasuredPowder m;
  m.source = "twin";
  m.particle_diameter = diameter;
  m.material_density = 7800;
  m.orifice_diameter = 12 * diameter;
  return m;
}

// The twin's tests, repeated, as the lab's file: the means, and the angle's and the rate's
// standard errors (the defaults' when a test ran once).
MeasuredPowder measure_twin(const scene::PipelineScene& scene, const MeasuredPowder& lab, double sliding, double rolling, int repeats) {
  const SimulatedTests twin = simulated_tests(scene, lab, 8);
  std::vector<double> angle, c, phi;
  for (int k = 0; k < repeats; ++k) {
    const TestResults r = run_tests(twin, sliding, rolling, 101 + std::uint64_t(k), fmt::format("the twin, seed {}", 101 + k));
    angle.push_back(r.repose_deg), c.push_back(r.beverloo_c), phi.push_back(r.solid_fraction);
  }
  MeasuredPowder m = lab;
  const MeanAndError a = mean_and_error(angle), flow = mean_and_error(c), packing = mean_and_error(phi);
  m.repose_deg = a.mean;
  m.apparent_density = packing.mean * m.material_density;
  m.flow_rate = flow.mean * m.apparent_density * beverloo_orifice(m.orifice_diameter, m.particle_diameter);
  if (repeats > 1) m.repose_error_deg = std::max(a.error, 0.1), m.flow_rate_error = std::max(flow.error / flow.mean, 0.001);
  return m;
}

}  // namespace

void calibration_round_trip(const scene::PipelineScene& scene, bool reduced, Output& out) {
  const double sliding = 0.4, rolling = 0.12;
  // Reduced: each test once, and coarser (2 mm grains: 4 mm spheres, the twin's 3 mm), so that
  // the suite's round trip takes about two minutes; by default four seeds a test, 1.2 mm grains.
  const int repeats = reduced ? 1 : 4;
  const MeasuredPowder measured = measure_twin(scene, lab_powder(reduced ? 2e-3 : 1.2e-3), sliding, rolling, repeats);
  std::filesystem::create_directories(out.work());
  diefill::write_file_atomic(out.work() / "measured.toml", measured_powder_toml(measured));
  CalibrateRequest c;
  c.measured = out.work() / "measured.toml";
  c.out = out.work() / "calibration";
  c.repeats = repeats;
  c.seed = scene.seed;
  if (run_calibrate(c) != 0) throw Interrupted{};
  std::ifstream in(c.out / "calibration.json");
  out.results = nlohmann::json::parse(in);
  out.results["true_sliding_friction"] = sliding;
  out.results["true_rolling_friction"] = rolling;
  out.results["repeats"] = repeats;
  out.results["lab_particle_diameter_m"] = measured.particle_diameter;
  out.results["measured_by_twin"] = {{"repose_deg", measured.repose_deg}, {"repose_error_deg", measured.repose_error_deg},
                                     {"apparent_density", measured.apparent_density}, {"flow_rate", measured.flow_rate},
                                     {"flow_rate_error", measured.flow_rate_error}};
  for (const char* name : {"sliding_friction", "rolling_friction"})
    out.results[name]["error"] = out.results[name]["value"].get<double>() - (name[0] == 's' ? sliding : rolling);
  // The same errors along the combinations the measurements fix best and worst.
  for (nlohmann::json& combination : out.results["fixed_combinations"])
    combination["error"] = combination["sliding_weight"].get<double>() * out.results["sliding_friction"]["error"].get<double>() +
                           combination["rolling_weight"].get<double>() * out.results["rolling_friction"]["error"].get<double>();
}

}  // namespace studies
