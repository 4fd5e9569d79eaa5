// The studies (`diefill study NAME`, reduced with 1.6 mm grains unless a test says otherwise): each
// runs end to end and checks the law it is about against a reference that does not come from
// the study's own output (a published range, the law's own prediction, a fixed tolerance from the
// literature); a fitted value meets a range only with its whole error bar inside.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>

#include <nlohmann/json.hpp>

#include "studies/studies.hpp"
#include "support.hpp"

namespace {

namespace fs = std::filesystem;

nlohmann::json run_study(const std::string& name, bool reduced, std::vector<std::string> overrides) {
  const fs::path out = fs::temp_directory_path() / fmt::format("diefill-study-{}-{}", name, ::getpid());
  fs::remove_all(out);
  studies::StudyRequest c;
  c.name = name;
  c.reduced = reduced;
  c.out = out;
  c.overrides = std::move(overrides);
  EXPECT_EQ(studies::run_study(c), 0);
  std::ifstream in(out / name / (name + ".json"));
  return nlohmann::json::parse(in);
}

nlohmann::json run_reduced(const std::string& name, std::vector<std::string> overrides = {"powder.coarse_graining=16"}) {
  return run_study(name, true, std::move(overrides));
}

// Whether the error bar x ± error lies inside [lo, hi]: a reference range is met when the whole
// bar is in it, so that a noisier study cannot pass more easily.
bool inside(double x, double error, double lo, double hi) { return x - error >= lo && x + error <= hi; }

// Discharge, reduced: the slot at its full layout with the scene's 0.8 mm grains (five widths of
// 5-12 grains, a container ten grains wide), the moving shoe with 1.6 mm grains.
TEST(Study, DischargeFollowsTheBeverlooSlotLawAndTheCriticalVelocityLaw) {
  const nlohmann::json r = run_reduced("discharge", {});
  const auto& bev = r["slot"]["beverloo"];
  // The slot law describes the measured rates: five widths, two parameters, residuals a few %.
  EXPECT_LT(bev["rms_relative_residual"].get<double>(), 0.05);
  // The published law: the slot form's C_s = 1.03 (Myers & Sellers, quoted by Nedderman 1992,
  // ch. 10) fits the rates as well, with a k inside the published 1.3-2.9 (Beverloo et al. 1961;
  // Nedderman 1992). C_s and k fitted together are correlated so strongly that five widths pin
  // neither to a published range: two runs of this scene gave C_s = 1.011 ± 0.025, k = 1.63 ±
  // 0.08 and C_s = 0.966 ± 0.040, k = 1.46 ± 0.14, the same rates within their noise.
  const auto& published = r["slot"]["beverloo_published_C_s"];
  EXPECT_LT(published["rms_relative_residual"].get<double>(), 0.05) << published.dump();
  EXPECT_TRUE(inside(published["k"], published["k_error"], 1.3, 2.9)) << published.dump();
  // The flow rate grows with the slot.
  const auto rates = r["slot"]["rates_kg_s"].get<std::vector<double>>();
  EXPECT_TRUE(std::is_sorted(rates.begin(), rates.end()));

  const auto& shoe = r["moving_shoe"];
  EXPECT_TRUE(shoe["delivered_mass_falls_above_v_c"].get<bool>()) << shoe.dump();
  const auto& critical = shoe["critical_velocity"];
  EXPECT_GE(critical["points"].get<int>(), 3);
  // docs/PHYSICS.md §3: v_c typically 0.05-0.4 m/s for free-flowing metal powders. Above it the
  // moving-container law, a steady rate through the opening for the time it is exposed (∝ 1/v),
  // gives n = 1 exactly; experiments report 1-2, the excess from rates that build up. The DEM has
  // the law's idealisation (a free-flowing powder, no air): n = 1 within 0.3, the lower third of
  // the experiments' spread.
  EXPECT_TRUE(inside(critical["v_c_m_s"], critical["v_c_error_m_s"], 0.05, 0.4)) << critical.dump();
  EXPECT_TRUE(inside(critical["n"], critical["n_error"], 0.7, 1.3)) << critical.dump();
  EXPECT_LT(critical["v_c_m_s"].get<double>(), shoe["speeds_m_s"][1].get<double>());
}

// Repose (1.6 mm grains; the scene's powder, μ = 0.5 and μ_r = 0.1, then μ = 0.1 and no rolling
// friction; six heaps (three at μ = 0.1, whose rise is 11°) and three drained beds of other seeds
// each): both angles rise with either friction by more than two combined standard errors (a
// test of a difference, so its errors belong in it; each angle's error is its beds' scatter, or
// their fits' where that is larger, and an outflow angle's fit error counts the disagreement of
// its two slopes). Zhou et al.'s correlation is a trend from another bench (docs/PHYSICS.md §3),
// so the scene's angles need only lie within 5° of it.
TEST(Study, ReposeAnglesRiseWithFrictionNearTheZhouCorrelation) {
  const nlohmann::json r = run_reduced("repose");
  const auto run_with = [&](double sliding, double rolling) {
    for (const auto& x : r["runs"])
      if (x["sliding_friction"].get<double>() == sliding && x["rolling_friction"].get<double>() == rolling) return x;
    ADD_FAILURE() << "no run with μ = " << sliding << ", μ_r = " << rolling;
    return nlohmann::json();
  };
  const nlohmann::json scene = run_with(0.5, 0.1), less_sliding = run_with(0.1, 0.1), no_rolling = run_with(0.5, 0.0);
  EXPECT_EQ(scene["heap_bed_angles_deg"].size(), 6u);
  EXPECT_EQ(scene["outflow_bed_angles_deg"].size(), 3u);
  for (const char* angle : {"heap", "outflow"}) {
    const std::string value = std::string(angle) + "_angle_deg", error = std::string(angle) + "_angle_error_deg";
    for (const nlohmann::json* lower : {&less_sliding, &no_rolling}) {
      EXPECT_GT(scene[value].get<double>() - (*lower)[value].get<double>(),
                2 * std::hypot(scene[error].get<double>(), (*lower)[error].get<double>()))
          << angle << ": " << scene.dump() << " against " << lower->dump();
    }
    EXPECT_NEAR(scene[value].get<double>(), scene["zhou_angle_deg"].get<double>(), 5.0) << angle << ": " << scene.dump();
  }
}

// Coarse graining (docs/PHYSICS.md §4) at grains of 0.8, 1.13 and 1.6 mm in a slot container
// that holds the coarsest eight across its slot and ten across its width, 4, 6 and 16 beds (each
// size's mean about as noisy as the others'); reduced, the ring die is not filled. With 2, 6 and
// 16 beds both checks held for six draws of the seed of six (docs/STUDIES.md, "coarse-graining").
TEST(Study, CoarseGrainingKeepsFlowAndReposeOnceTheBoundaryIsCorrected) {
  const nlohmann::json r = run_reduced("coarse-graining", {});
  const auto& inv = r["invariance"];
  // The slot's k·αd term is large here: uncorrected, the rates differ by far more than 5 %.
  EXPECT_GT(inv["flow_rate_spread"]["measured"].get<double>(), 0.05) << inv.dump();
  // One Beverloo law makes the three rates one within the seed study's 5 %, with a k in the
  // published 1.3-2.9 (Beverloo et al. 1961; Nedderman 1992). The textbook k = 1.5 is reported,
  // not asserted: these spheres' k is higher (docs/STUDIES.md, "coarse-graining").
  EXPECT_LE(inv["flow_rate_spread_beverloo_fitted_k"]["measured"].get<double>(), 0.05) << inv.dump();
  const double k = r["settings"]["beverloo_k_that_makes_the_rates_one_law"];
  EXPECT_GE(k, 1.3);
  EXPECT_LE(k, 2.9);
  // Outflow angles (each the mean of its size's beds) within the seed study's 2°.
  std::vector<double> angles;
  for (const auto& f : r["factors"]) angles.push_back(f["slot"]["outflow_angle_deg"]);
  const auto [low, high] = std::minmax_element(angles.begin(), angles.end());
  EXPECT_LE(*high - *low, 2.0) << r["factors"].dump();
  // The ring is filled at the default size only: its annulus is 3 to 6 of these grains wide, far
  // from the 20 docs/PHYSICS.md §4 asks for, so their fill would test no invariance.
}

// The speed-accuracy sweep on the ring die (1.6 mm grains): the cost laws it rests on, read
// from step counts, not timings (docs/PHYSICS.md §4-5).
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
  // between 10^0.4 (Hertz-limited) and 10^0.5 (Rayleigh-limited) times longer. A run the overlap
  // check stops still reports the step it stepped with: the softened grains overlap 10^0.4 times
  // deeper, close to the check's limit (one run stopped at 0.252 of the radius for 0.25).
  const double dt = reference["time_step_s"];
  EXPECT_NEAR(run.at("time step x 2")["time_step_s"].get<double>() / dt, 2.0, 1e-9);
  const double softened = run.at("stiffness / 10")["time_step_s"].get<double>() / dt;
  EXPECT_GE(softened, std::pow(10.0, 0.4) * (1 - 1e-9));
  EXPECT_LE(softened, std::pow(10.0, 0.5) * (1 + 1e-9));
  // Another seed changes the field (the noise floor is not zero) but not the fill by much.
  ASSERT_TRUE(run.at("the same, another seed")["ran"].get<bool>());
  EXPECT_GT(r["noise_floor_field_error"].get<double>(), 0.0);
  EXPECT_LT(run.at("the same, another seed")["fill_ratio_error"].get<double>(), 0.05);
  EXPECT_EQ(r["budgets"].size(), 3u);
}

// Cross-validation at the default size (0.8 mm grains, six rolling frictions; the reduced 1.6 mm
// version calibrated μ_r = -0.08 on the flow for a true 0.1): calibrated on the outflow angle,
// rolling friction comes out as the scene's and predicts the flow rate; calibrated on the flow
// rate, it predicts the angle. Tolerances fixed beforehand, not from the study's own errors: 3° in
// angle (about the spread of repeated angle-of-repose tests on one powder) and 10 % in flow
// rate; μ_r within ±0.05 of the truth, half the scene's value.
TEST(Study, CrossValidationPredictsFlowFromReposeAndReposeFromFlow) {
  const nlohmann::json r = run_study("cross-validation", false, {});
  const auto& angle_map = r["maps"]["angle_deg"];
  // The angle rises with rolling friction (Zhou et al.'s trend), clearly: else nothing calibrates.
  EXPECT_GT(angle_map["slope"].get<double>(), 2 * angle_map["slope_error"].get<double>()) << angle_map.dump();
  const double truth = r["true_rolling_friction"];
  for (const char* direction : {"calibrated_on_angle", "calibrated_on_flow"})
    EXPECT_NEAR(r[direction]["rolling_friction"].get<double>(), truth, 0.05) << direction << ": " << r[direction].dump();
  const auto& flow = r["calibrated_on_angle"]["rate_kg_s"];
  EXPECT_NEAR(flow["predicted"].get<double>() / flow["observed"].get<double>(), 1.0, 0.10) << flow.dump();
  const auto& angle = r["calibrated_on_flow"]["angle_deg"];
  EXPECT_NEAR(angle["predicted"].get<double>(), angle["observed"].get<double>(), 3.0) << angle.dump();
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
