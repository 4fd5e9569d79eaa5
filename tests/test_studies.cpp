// The reduced studies (`diefill study NAME --reduced`, 1.6 mm grains unless a test says
// otherwise): each runs end to end and
// checks the law it is about. Tolerances are statistical (two standard errors of the study's own
// fits) or come from PHYSICS.md's stated ranges; each says which.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>

#include <nlohmann/json.hpp>

#include "app/commands.hpp"
#include "support.hpp"

namespace {

namespace fs = std::filesystem;

nlohmann::json run_reduced(const std::string& name, std::vector<std::string> overrides = {"powder.coarse_graining=16"}) {
  const fs::path out = fs::temp_directory_path() / fmt::format("diefill-study-{}-{}", name, ::getpid());
  fs::remove_all(out);
  app::StudyCommand c;
  c.name = name;
  c.reduced = true;
  c.out = out;
  c.overrides = std::move(overrides);
  EXPECT_EQ(app::run_study(c), 0);
  std::ifstream in(out / name / (name + ".json"));
  return nlohmann::json::parse(in);
}

// Whether x lies within `sigmas` standard errors of the interval [lo, hi].
bool consistent_with(double x, double error, double lo, double hi, double sigmas = 2) {
  return x + sigmas * error >= lo && x - sigmas * error <= hi;
}

TEST(Study, DischargeFollowsTheBeverlooSlotLawAndTheCriticalVelocityLaw) {
  const nlohmann::json r = run_reduced("discharge");
  const auto& bev = r["slot"]["beverloo"];
  // The slot law describes the measured rates: three widths, two parameters, residuals a few %.
  EXPECT_LT(bev["rms_relative_residual"].get<double>(), 0.05);
  // PHYSICS.md §3: C_s about 1 (taken as 0.75-1.25), k 1.4-2.9 for spheres; the fit from three
  // widths of a small container is uncertain, so agreement within two standard errors.
  EXPECT_TRUE(consistent_with(bev["C_s"], bev["C_s_error"], 0.75, 1.25)) << bev.dump();
  EXPECT_TRUE(consistent_with(bev["k"], bev["k_error"], 1.4, 2.9)) << bev.dump();
  // The flow rate grows with the slot.
  const auto rates = r["slot"]["rates_kg_s"].get<std::vector<double>>();
  EXPECT_TRUE(std::is_sorted(rates.begin(), rates.end()));

  const auto& shoe = r["moving_shoe"];
  EXPECT_TRUE(shoe["delivered_mass_falls_above_v_c"].get<bool>()) << shoe.dump();
  const auto& critical = shoe["critical_velocity"];
  EXPECT_GE(critical["points"].get<int>(), 3);
  // Above v_c the delivered mass falls as v^-n; the moving-container law gives n = 1 and
  // die-filling experiments 1-2 (PHYSICS.md §3): within two standard errors of that range.
  EXPECT_TRUE(consistent_with(critical["n"], critical["n_error"], 1.0, 2.0)) << critical.dump();
  EXPECT_GT(critical["v_c_m_s"].get<double>(), 0.0);
  EXPECT_LT(critical["v_c_m_s"].get<double>(), shoe["speeds_m_s"][1].get<double>());
}

// Repose (1.6 mm grains; the scene's powder, μ = 0.5 and μ_r = 0.1, then less sliding and no
// rolling friction): both angles rise with either friction by more than two combined standard
// errors. Zhou et al.'s correlation is a trend from another bench (PHYSICS.md §3), so the
// scene's angles need only lie within 5° of it, plus two standard errors.
TEST(Study, ReposeAnglesRiseWithFrictionNearTheZhouCorrelation) {
  const nlohmann::json r = run_reduced("repose");
  const auto run_with = [&](double sliding, double rolling) {
    for (const auto& x : r["runs"])
      if (x["sliding_friction"].get<double>() == sliding && x["rolling_friction"].get<double>() == rolling) return x;
    ADD_FAILURE() << "no run with μ = " << sliding << ", μ_r = " << rolling;
    return nlohmann::json();
  };
  const nlohmann::json scene = run_with(0.5, 0.1), less_sliding = run_with(0.25, 0.1), no_rolling = run_with(0.5, 0.0);
  for (const char* angle : {"heap", "outflow"}) {
    const std::string value = std::string(angle) + "_angle_deg", error = std::string(angle) + "_angle_error_deg";
    for (const nlohmann::json* lower : {&less_sliding, &no_rolling}) {
      EXPECT_GT(scene[value].get<double>() - (*lower)[value].get<double>(),
                2 * std::hypot(scene[error].get<double>(), (*lower)[error].get<double>()))
          << angle << ": " << scene.dump() << " against " << lower->dump();
    }
    EXPECT_NEAR(scene[value].get<double>(), scene["zhou_angle_deg"].get<double>(), 5 + 2 * scene[error].get<double>())
        << angle << ": " << scene.dump();
  }
}

// Coarse graining (PHYSICS.md §4) at grains of 0.8, 1.13 and 1.6 mm in one slot container (the
// coarsest five grains across its slot and its length); reduced, the ring die is not filled.
TEST(Study, CoarseGrainingKeepsFlowAndReposeOnceTheBoundaryIsCorrected) {
  const nlohmann::json r = run_reduced("coarse-graining", {});
  const auto& inv = r["invariance"];
  // The slot's k·αd term is large here: uncorrected, the rates differ by far more than 5 %;
  // corrected with k = 1.5 (PHYSICS.md §3), they meet the seed study's 5 %.
  EXPECT_GT(inv["flow_rate_spread"]["measured"].get<double>(), 0.05) << inv.dump();
  EXPECT_LT(inv["flow_rate_spread_beverloo_corrected"]["measured"].get<double>(), 0.05) << inv.dump();
  // And the k that makes the three rates one law is a Beverloo k for spheres (1.4-2.9).
  const double k = r["settings"]["beverloo_k_that_makes_the_rates_one_law"];
  EXPECT_GE(k, 1.4);
  EXPECT_LE(k, 2.9);
  // Outflow angles within the seed study's 2°, allowing two standard errors of the extreme pair.
  std::vector<std::pair<double, double>> angles;
  for (const auto& f : r["factors"]) angles.push_back({f["slot"]["outflow_angle_deg"], f["slot"]["outflow_angle_error_deg"]});
  const auto [low, high] = std::minmax_element(angles.begin(), angles.end());
  EXPECT_LE(high->first - low->first, 2.0 + 2 * std::hypot(high->second, low->second)) << inv.dump();
  // The ring is filled at the default size only: its annulus is 3 to 6 of these grains wide, far
  // from the 20 PHYSICS.md §4 asks for, so their fill would test no invariance.
}

// The speed-accuracy sweep on the ring die (1.6 mm grains): the cost laws it rests on, read
// from step counts, not timings (PHYSICS.md §4-5).
TEST(Study, SpeedAccuracySweepFollowsTheCostLaws) {
  const nlohmann::json r = run_reduced("speed-accuracy");
  std::map<std::string, nlohmann::json> run;
  for (const auto& x : r["runs"]) {
    run[x["label"]] = x;
    if (!x["ran"].get<bool>()) {
      EXPECT_FALSE(x["stopped_by"].get<std::string>().empty()) << x.dump();
    }
  }
  const auto& reference = run.at("the scene's settings");
  ASSERT_TRUE(reference["ran"].get<bool>());
  // Grains √2 coarser: N as α⁻³ and the step as α, so particle-steps as α⁻⁴; the shoe's grain
  // count and the step's Hertz limit make it approximate: within ±0.5 in the exponent.
  const auto& coarser = run.at("grains √2 coarser");
  const double exponent = std::log(coarser["particle_steps"].get<double>() / reference["particle_steps"].get<double>()) /
                          std::log(coarser["coarse_graining"].get<double>() / reference["coarse_graining"].get<double>());
  EXPECT_NEAR(exponent, -4.0, 0.5);
  // The step: twice the fraction gives exactly twice the step; a tenth of the stiffness a step
  // between 10^0.4 (Hertz-limited) and 10^0.5 (Rayleigh-limited) times longer.
  const double dt = reference["time_step_s"];
  EXPECT_NEAR(run.at("time step x 2")["time_step_s"].get<double>() / dt, 2.0, 1e-9);
  const double softened = run.at("stiffness / 10")["time_step_s"].get<double>() / dt;
  EXPECT_GE(softened, std::pow(10.0, 0.4) * (1 - 1e-9));
  EXPECT_LE(softened, std::pow(10.0, 0.5) * (1 + 1e-9));
  // Another seed changes the field (the noise floor is not zero) but not the fill by much.
  EXPECT_GT(r["noise_floor_field_error"].get<double>(), 0.0);
  EXPECT_LT(run.at("the same, another seed")["fill_ratio_error"].get<double>(), 0.05);
  EXPECT_EQ(r["budgets"].size(), 3u);
}

// Cross-validation (1.6 mm grains): calibrated on the outflow angle, the rolling friction comes
// out as the scene's and predicts the flow rate; calibrated on the flow rate, it predicts the
// angle. Agreement means within two combined standard errors (the observation's and the maps'
// scatter, propagated through the calibration).
TEST(Study, CrossValidationPredictsFlowFromReposeAndReposeFromFlow) {
  const nlohmann::json r = run_reduced("cross-validation");
  const auto& angle_map = r["maps"]["angle_deg"];
  // The angle rises with rolling friction (Zhou et al.'s trend), clearly: else nothing calibrates.
  EXPECT_GT(angle_map["slope"].get<double>(), 2 * angle_map["slope_error"].get<double>()) << angle_map.dump();
  const auto& on_angle = r["calibrated_on_angle"];
  EXPECT_NEAR(on_angle["rolling_friction"].get<double>(), r["true_rolling_friction"].get<double>(),
              2 * on_angle["rolling_friction_error"].get<double>())
      << on_angle.dump();
  for (const char* direction : {"calibrated_on_angle", "calibrated_on_flow"}) {
    const auto& c = r[direction];
    const auto& p = c.contains("rate_kg_s") ? c["rate_kg_s"] : c["angle_deg"];
    EXPECT_NEAR(p["predicted"].get<double>(), p["observed"].get<double>(),
                2 * std::hypot(p["predicted_error"].get<double>(), p["observed_error"].get<double>()))
        << direction << ": " << c.dump();
  }
}

// Each method probed below and beyond its limit: below, the run passes its checks and its
// result is right; beyond, a check stops or refuses it. No run may end wrong and unnoticed.
TEST(Study, StabilityMapCatchesEveryFailure) {
  const nlohmann::json r = run_reduced("stability");
  std::map<std::string, std::vector<std::pair<double, std::string>>> by_probe;
  for (const auto& p : r["probes"]) {
    EXPECT_NE(p["outcome"].get<std::string>(), "ran, wrong and not caught") << p.dump();
    by_probe[p["probe"]].push_back({p["ratio"], p["outcome"]});
  }
  EXPECT_EQ(by_probe.size(), 4u);
  for (auto& [probe, runs] : by_probe) {
    std::sort(runs.begin(), runs.end());
    EXPECT_EQ(runs.front().second, "ran, checks passed") << probe;
    EXPECT_TRUE(runs.back().second == "stopped by a stability check" || runs.back().second == "refused before running") << probe;
  }
}

}  // namespace
