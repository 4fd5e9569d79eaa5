// Seed ensembles (pipeline/ensemble.hpp) and grain-size ladders (pipeline/extrapolate.hpp): the
// standard error of the mean against synthetic seeds of known variance, the report's means with
// their errors beside them, the fill curve's band, the affine fit against known laws and Monte
// Carlo, χ²'s quantiles against tables, and the cavity's feature widths against its geometry.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mesh/feature_width.hpp"
#include "mesh/shapes.hpp"
#include "pipeline/ensemble.hpp"
#include "pipeline/extrapolate.hpp"
#include "pipeline/run_plan.hpp"
#include "core/error.hpp"
#include "postprocess/ensemble_stats.hpp"

using Vec3 = Eigen::Vector3d;

namespace {

// Synthetic seeds of a field: voxel v drawn N times from a normal distribution of known mean
// μ_v and standard deviation σ_v.
std::vector<std::vector<double>> synthetic_seeds(int seeds, const std::vector<double>& mu, const std::vector<double>& sigma,
                                                 std::uint64_t seed) {
  std::mt19937_64 random(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<std::vector<double>> out(std::size_t(seeds), std::vector<double>(mu.size()));
  for (auto& field : out)
    for (std::size_t v = 0; v < mu.size(); ++v) field[v] = mu[v] + sigma[v] * normal(random);
  return out;
}

}  // namespace

// Over 20,000 voxels of known σ_v (0.01 to 0.05): N·se²/σ² averages 1 to within three of its own
// standard deviations (√(2/((N−1)V)) for normal samples), and the mean lies within two
// standard errors of the truth in 95.4 % of the voxels (normal quantile), for N = 3 and 8.
TEST(EnsembleStats, StandardErrorMatchesTheSeedsKnownVariance) {
  const std::size_t voxels = 20000;
  std::vector<double> mu(voxels), sigma(voxels);
  for (std::size_t v = 0; v < voxels; ++v) mu[v] = 0.5 + 0.1 * std::sin(double(v)), sigma[v] = 0.01 + 0.04 * double(v % 97) / 96;
  for (const int n : {3, 8}) {
    const post::MeanAndError m = post::mean_and_error(synthetic_seeds(n, mu, sigma, 7 + std::uint64_t(n)));
    double ratio = 0;
    std::size_t within = 0;
    for (std::size_t v = 0; v < voxels; ++v) {
      ratio += double(n) * m.error[v] * m.error[v] / (sigma[v] * sigma[v]) / double(voxels);
      within += std::abs(m.mean[v] - mu[v]) <= 2 * sigma[v] / std::sqrt(double(n));
    }
    EXPECT_NEAR(ratio, 1.0, 3 * std::sqrt(2.0 / (double(n - 1) * double(voxels)))) << n << " seeds";
    // The fraction within 2σ/√N: 0.9545, a binomial spread of 0.0015 over the voxels.
    EXPECT_NEAR(double(within) / double(voxels), 0.9545, 4 * 0.0015) << n << " seeds";
  }
  // Two seeds: the standard error is half their difference, exactly as arithmetic gives it.
  const post::MeanAndError two = post::mean_and_error({{0.50, std::nan("")}, {0.56, 0.2}});
  EXPECT_DOUBLE_EQ(two.mean[0], 0.53);
  EXPECT_NEAR(two.error[0], 0.03, 1e-15);
  EXPECT_TRUE(std::isnan(two.mean[1]) && std::isnan(two.error[1]));
}

// The report's blocks: a figure that differs between the seeds is their mean with its standard
// error beside it (0.50, 0.53, 0.56: 0.53 and 0.03/√3), arrays element by element; a figure the
// same in every seed (the voxel, the cavity) stays as it is, with no error; text is the first's.
TEST(EnsembleReport, VaryingFiguresGetTheirStandardErrorBesideThem) {
  const auto block = [](double fill, double p0, const char* curve) {
    return nlohmann::json{{"fill_ratio", fill}, {"voxel_m", 1.6e-3}, {"curve", curve},
                          {"profiles", {{"z", {{"solid_fraction", {p0, 0.4}}, {"position_m", {0.001, 0.002}}}}}}};
  };
  const nlohmann::json m = pipeline::mean_with_stderr({block(0.50, 0.1, "a.csv"), block(0.53, 0.2, "b.csv"), block(0.56, 0.3, "c.csv")});
  EXPECT_NEAR(m["fill_ratio"].get<double>(), 0.53, 1e-15);
  EXPECT_NEAR(m["fill_ratio_stderr"].get<double>(), 0.03 / std::sqrt(3.0), 1e-15);
  EXPECT_EQ(m["voxel_m"].get<double>(), 1.6e-3);
  EXPECT_FALSE(m.contains("voxel_m_stderr"));
  EXPECT_EQ(m["curve"], "a.csv");
  const nlohmann::json& z = m["profiles"]["z"];
  EXPECT_NEAR(z["solid_fraction"][0].get<double>(), 0.2, 1e-15);
  EXPECT_NEAR(z["solid_fraction_stderr"][0].get<double>(), 0.1 / std::sqrt(3.0), 1e-15);
  EXPECT_NEAR(z["solid_fraction_stderr"][1].get<double>(), 0.0, 1e-15);  // the same 0.4 thrice, to rounding
  EXPECT_FALSE(z.contains("position_m_stderr"));
}

// The fill curves' band: two seeds whose mass grows linearly at different rates give, sample by
// sample, the mean mass and half their difference; the mean ends with the shorter curve.
TEST(EnsembleCurve, BandIsHalfTheTwoSeedsDifference) {
  std::vector<pipeline::FillSample> a, b;
  for (int n = 0; n < 10; ++n) a.push_back({0.002 * n, 0.0, 10 * n, 1e-4 * n});
  for (int n = 0; n < 9; ++n) b.push_back({0.002 * n, 0.0, 12 * n, 1.4e-4 * n});
  const auto [mean, band] = pipeline::mean_curve({a, b});
  ASSERT_EQ(mean.size(), 9u);
  for (std::size_t n = 0; n < mean.size(); ++n) {
    EXPECT_NEAR(mean[n].mass, 1.2e-4 * double(n), 1e-18);
    EXPECT_NEAR(band.mass_stderr[n], 0.2e-4 * double(n), 1e-18);
    EXPECT_NEAR(band.grains[n], 11.0 * double(n), 1e-12);
    EXPECT_NEAR(band.grains_stderr[n], 1.0 * double(n), 1e-12);
  }
}

namespace {

std::vector<pipeline::LevelValue> affine_levels(double intercept, double slope, double curvature, const std::vector<double>& se,
                                           std::mt19937_64* random) {
  const std::vector<double> diameters = {2.26e-3, 1.6e-3, 1.13e-3};
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<pipeline::LevelValue> out;
  for (std::size_t k = 0; k < diameters.size(); ++k) {
    const double d = diameters[k];
    out.push_back({d, intercept + slope * d + curvature * d * d + (random ? se[k] * normal(*random) : 0.0), se[k]});
  }
  return out;
}

}  // namespace

// A law the levels follow exactly is recovered to rounding, with χ² = 0.
TEST(Extrapolation, RecoversAnExactAffineLaw) {
  const pipeline::AffineFit fit = pipeline::fit_affine(affine_levels(0.60, -30, 0, {0.001, 0.002, 0.003}, nullptr));
  EXPECT_NEAR(fit.intercept, 0.60, 1e-12);
  EXPECT_NEAR(fit.slope, -30, 1e-9);
  EXPECT_NEAR(fit.chi2, 0, 1e-18);
  EXPECT_EQ(fit.dof, 1);
}

// 4000 ladders with Gaussian noise of known standard errors: the estimates at d* = 0.1 mm scatter
// as the fit's own standard error says (before the Birge factor), within 5 %; and an affine law is
// refused as curved about as often as χ²'s 99 % quantile allows (1 %, at most 2.5 % here), while
// a law with a real curvature (50 000 /m² × d², whose noise-free levels lie off their best line at
// χ² = 24.6: a non-central χ² that passes 6.63 99 % of the time) is refused 95 times in 100 or more.
TEST(Extrapolation, StandardErrorIsTheEstimatesSpreadAndOnlyCurvatureIsRefused) {
  std::mt19937_64 random(45);
  const std::vector<double> se = {0.004, 0.0025, 0.0015};
  const double target = 0.1e-3, truth = 0.60 - 30 * target;
  double sum = 0, squares = 0, claimed = 0;
  int refused = 0;
  const int ladders = 4000;
  for (int n = 0; n < ladders; ++n) {
    const pipeline::AffineFit fit = pipeline::fit_affine(affine_levels(0.60, -30, 0, se, &random));
    const double e = fit.at(target) - truth;
    sum += e, squares += e * e;
    claimed += fit.stderr_at(target) / std::sqrt(fit.birge) / ladders;
    refused += !pipeline::refuse_curved(fit).empty();
  }
  const double spread = std::sqrt(squares / ladders - (sum / ladders) * (sum / ladders));
  EXPECT_NEAR(spread / claimed, 1.0, 0.05);
  EXPECT_LE(refused, int(0.025 * ladders));
  EXPECT_NEAR(pipeline::fit_affine(affine_levels(0.60, -30, 5e4, se, nullptr)).chi2, 24.58, 0.01);
  int curved = 0;
  for (int n = 0; n < 100; ++n) curved += !pipeline::refuse_curved(pipeline::fit_affine(affine_levels(0.60, -30, 5e4, se, &random))).empty();
  EXPECT_GE(curved, 95);
}

// χ²'s 99 % quantiles against the published table (Abramowitz and Stegun 26.4), the Wilson-Hilferty
// approximation beyond ten degrees of freedom within 0.5 %.
TEST(Extrapolation, ChiSquareQuantilesMatchTheTables) {
  EXPECT_DOUBLE_EQ(pipeline::chi2_quantile_99(1), 6.635);
  EXPECT_DOUBLE_EQ(pipeline::chi2_quantile_99(3), 11.345);
  EXPECT_NEAR(pipeline::chi2_quantile_99(15) / 30.578, 1.0, 0.005);
  EXPECT_NEAR(pipeline::chi2_quantile_99(20) / 37.566, 1.0, 0.005);
  EXPECT_NEAR(pipeline::chi2_quantile_99(30) / 50.892, 1.0, 0.005);
}

// Pooled level errors: two levels whose seeds scatter as 1/√(grains) with one constant get their
// own errors back; a level with few grains gets the larger error.
TEST(Extrapolation, PooledErrorsScaleWithTheGrainsInTheCavity) {
  // Level 1: 3 seeds, 400 grains, se 0.003; level 2: 3 seeds, 1600 grains, se 0.0015 (half).
  const std::vector<double> pooled = pipeline::pooled_stderr({{3, 0.003, 400}, {3, 0.0015, 1600}});
  EXPECT_NEAR(pooled[0], 0.003, 1e-12);
  EXPECT_NEAR(pooled[1], 0.0015, 1e-12);
}

// The cavity's features: the ring's annulus is 5 mm wide over most of its volume (its walls face
// each other across it), a 1.2 mm slot 1.2 mm, and the disc has no feature narrower than its
// 20 mm: its floor meets its wall at a convex edge, and its top is open. A ladder whose coarsest
// grains are 2.26 mm is refused on the ring (2.2 grains across), naming α ≤ 10 (5 mm over five
// 0.1 mm grains), and taken on the disc.
TEST(Extrapolation, FeatureWidthsOfAnnulusSlotAndDisc) {
  const double h = 0.25e-3;
  const mesh::FeatureWidths ring = mesh::feature_widths(mesh::ring_cavity(20e-3, 10e-3, 10e-3, 1e-6), 0.0, h);
  ASSERT_NE(ring.narrowest(), nullptr);
  EXPECT_NEAR(ring.narrowest()->width, 5e-3, 2 * h);
  EXPECT_GT(ring.share_below(5.5e-3), 0.4);
  const mesh::FeatureWidths slot = mesh::feature_widths(mesh::box_solid(Vec3(-5e-3, -0.6e-3, -8e-3), Vec3(5e-3, 0.6e-3, 0)), 0.0, 0.1e-3);
  ASSERT_NE(slot.narrowest(), nullptr);
  EXPECT_NEAR(slot.narrowest()->width, 1.2e-3, 0.2e-3);
  const mesh::FeatureWidths disc = mesh::feature_widths(mesh::ring_cavity(20e-3, 0, 10e-3, 1e-6), 0.0, h);
  EXPECT_EQ(disc.share_below(19e-3), 0.0);
  const pipeline::Refusal r = pipeline::refuse_thin_features(ring, 2.26e-3, 0.1e-3);
  EXPECT_NE(r.reason.find("5 mm wide"), std::string::npos) << r.reason;
  EXPECT_NEAR(r.alpha_needed, 10, 0.6);
  EXPECT_TRUE(pipeline::refuse_thin_features(disc, 2.26e-3, 0.1e-3).reason.empty());
}

// `--budget`'s durations, and what is not one.
TEST(Plan, DurationsParse) {
  EXPECT_EQ(pipeline::parse_duration("90"), 90);
  EXPECT_EQ(pipeline::parse_duration("90s"), 90);
  EXPECT_EQ(pipeline::parse_duration("30m"), 1800);
  EXPECT_EQ(pipeline::parse_duration("2h"), 7200);
  EXPECT_EQ(pipeline::parse_duration("1h30m"), 5400);
  for (const char* bad : {"", "3 days", "h", "-5m", "0"}) EXPECT_THROW(pipeline::parse_duration(bad), diefill::InputError) << bad;
}
