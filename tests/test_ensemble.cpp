// Seed ensembles (pipeline/ensemble.hpp): the standard error of the mean against synthetic
// seeds of known variance, the report's means with their errors beside them, and the fill
// curve's band, each against what it must be by construction of the synthetic data.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "pipeline/ensemble.hpp"
#include "postprocess/ensemble_stats.hpp"

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
  const nlohmann::json m = app::mean_with_stderr({block(0.50, 0.1, "a.csv"), block(0.53, 0.2, "b.csv"), block(0.56, 0.3, "c.csv")});
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
  std::vector<app::FillSample> a, b;
  for (int n = 0; n < 10; ++n) a.push_back({0.002 * n, 0.0, 10 * n, 1e-4 * n});
  for (int n = 0; n < 9; ++n) b.push_back({0.002 * n, 0.0, 12 * n, 1.4e-4 * n});
  const auto [mean, band] = app::mean_curve({a, b});
  ASSERT_EQ(mean.size(), 9u);
  for (std::size_t n = 0; n < mean.size(); ++n) {
    EXPECT_NEAR(mean[n].mass, 1.2e-4 * double(n), 1e-18);
    EXPECT_NEAR(band.mass_stderr[n], 0.2e-4 * double(n), 1e-18);
    EXPECT_NEAR(band.grains[n], 11.0 * double(n), 1e-12);
    EXPECT_NEAR(band.grains_stderr[n], 1.0 * double(n), 1e-12);
  }
}
