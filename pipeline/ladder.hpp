#pragma once
// `diefill run DIE --ladder A1,A2,A3 [--extrapolate-to ALPHA] [--seeds N]` (docs/INTERFACE.md,
// "Grain-size ladders"): the scene at three or more coarse-graining levels, each a seed ensemble,
// and the fill extrapolated, affine in the grain diameter (docs/PHYSICS.md §4.1), to the
// powder's real size or another, with an error from the fit and the seeds' noise; refused where
// the levels are outside the law's range.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dem/exchange.hpp"
#include "pipeline/die_fill.hpp"

namespace pipeline {

struct Ladder {
  std::vector<double> alphas;            // coarse-graining levels, three or more, distinct
  std::optional<double> extrapolate_to;  // α of the answer; none: 1, the real powder
  int seeds = 2;                         // per level
};

// Parses A1,A2,A3,...; InputError naming --ladder when it is not three or more distinct numbers in [1, 200].
Ladder parse_ladder(const std::string& text);

// Checks every level's scene and the cavity's features first (a refusal before any run), then
// runs each level's ensemble into OUT/powder.coarse_graining=A/ (its seeds in
// .../simulation.seed=K/<die>/), all on the finest level's voxels and elements, and writes into
// OUT/<die>/ the finest level's report with an `extrapolation` block, extrapolated.vdb (the
// extrapolated solid fraction and its standard error per voxel), ladder.csv and
// extrapolation.png. Levels off the line beyond their noise: the outputs are written, the
// block says why, and InputError follows.
DieRun run_ladder(const std::function<scene::PipelineScene(const std::vector<std::string>& overrides)>& load, const Ladder& ladder,
                  const std::shared_ptr<dem::Exchange>& ranks);

}  // namespace pipeline
