#pragma once
// Statistics over a seed ensemble's realisations (pipeline/ensemble.hpp): the mean and the
// standard error of the mean, value by value.
#include <vector>

namespace post {

struct MeanAndError {
  std::vector<double> mean, error;  // the mean and its standard error
};

// Over N ≥ 2 samples of equal length, element by element: the mean and s/√N, s the sample
// standard deviation (N − 1 in its denominator); NaN where any sample is NaN. Summed in the
// samples' order, so that the same samples give the same bits.
MeanAndError mean_and_error(const std::vector<std::vector<double>>& samples);

// The same for one value per sample.
double standard_error(const std::vector<double>& values);

}  // namespace post
