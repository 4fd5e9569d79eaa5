#pragma once
// `diefill calibrate MEASURED.toml`: the sliding and rolling friction of the scene's contact laws
// fitted to what a lab measured on its powder (measured_powder.hpp). The same tests are simulated
// on coarse-grained spheres, at frictions spread over a design, and each result is mapped as a
// smooth function of the two frictions; the frictions whose maps meet the measurements best, with
// their confidence intervals, are written as a [[materials]] block (docs/INTERFACE.md, "Your
// powder").
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "studies/measured_powder.hpp"
#include "studies/study_kit.hpp"

namespace studies {

struct CalibrateRequest {
  std::filesystem::path measured;
  std::filesystem::path out = "out/calibration";
  std::vector<std::string> overrides;  // scene keys: the contact laws, the stiffness, ...
  bool resume = false;                 // keep the finished tests of an interrupted calibration
  int repeats = 2;                     // seeds per design point: the maps' noise falls as 1/√repeats
  std::optional<int> threads;
  std::uint64_t seed = 1;
};
// Returns the exit status (130 when interrupted: the finished tests stay for --resume).
int run_calibrate(const CalibrateRequest& request);

// Beverloo's k for these spheres: the coarse-graining study's (docs/STUDIES.md: 1.81 made the
// flow rates of three grain sizes one law). It is not known well for a funnel: orifices of 6 and
// 8 grains gave C 0.915 and 0.779 with it (three seeds each), one law with k = 0.8. The fit counts
// that as a model error of the simulated C: ±beverloo_k_error in k.
inline constexpr double beverloo_k = 1.8, beverloo_k_error = 0.6;
// Beverloo's law through a round orifice, Ẇ = C ρ_b √g (D − k d)^{5/2}: the factor after C ρ_b.
double beverloo_orifice(double orifice, double d);

// The simulated tests: the powder at its coarse grain size, the funnel's orifice `orifice_grains`
// of them wide under a cone of the lab funnel's angle.
struct SimulatedTests {
  Powder powder;
  double orifice_grains = 6;
  double funnel_half_angle_deg = 30;
};
SimulatedTests simulated_tests(const scene::PipelineScene& scene, const MeasuredPowder& measured, double orifice_grains);

// What the tests give for one pair of frictions: the heap's angle [°], the orifice's C and the
// poured bed's solid fraction.
struct TestResults {
  double repose_deg = 0, beverloo_c = 0, solid_fraction = 0;
};
TestResults run_tests(const SimulatedTests& tests, double sliding, double rolling, std::uint64_t seed, const std::string& label);

}  // namespace studies
