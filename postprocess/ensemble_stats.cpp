#include "postprocess/ensemble_stats.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace post {

MeanAndError mean_and_error(const std::vector<std::vector<double>>& samples) {
  if (samples.size() < 2) throw std::invalid_argument("mean_and_error needs two samples or more");
  const std::size_t n = samples.front().size();
  for (const auto& s : samples)
    if (s.size() != n) throw std::invalid_argument("mean_and_error: samples of different lengths");
  const double count = double(samples.size());
  MeanAndError out{std::vector<double>(n, 0.0), std::vector<double>(n, 0.0)};
  for (std::size_t i = 0; i < n; ++i) {
    double sum = 0;
    for (const auto& s : samples) sum += s[i];
    const double mean = sum / count;
    double squares = 0;
    for (const auto& s : samples) squares += (s[i] - mean) * (s[i] - mean);
    out.mean[i] = mean;
    out.error[i] = std::isfinite(mean) ? std::sqrt(squares / (count - 1) / count) : std::numeric_limits<double>::quiet_NaN();
  }
  return out;
}

double standard_error(const std::vector<double>& values) {
  std::vector<std::vector<double>> samples;
  for (double v : values) samples.push_back({v});
  return mean_and_error(samples).error.front();
}

}  // namespace post
