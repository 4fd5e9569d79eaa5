#pragma once
// The shoe's pass over the die and the die's settling: one run of the stepping loop from the
// settled shoe (or from the checkpoint an interrupted run left), with snapshots and progress.
#include <filesystem>
#include <optional>

#include "dem/state.hpp"
#include "pipeline/fill_curve.hpp"
#include "pipeline/run_loop.hpp"
#include "pipeline/walls.hpp"

namespace pipeline {

struct FillResult {
  dem::State state;  // split over ranks: the whole state on rank 0, none elsewhere
  LoopResult loop;
  double dt = 0;  // [s]
  std::vector<FillSample> curve;  // from the fill's start (a resumed run: the interrupted run's samples, then its own)
};

// nullopt when Ctrl-C stopped it (a checkpoint is in `dir`); StabilityError when a check did.
// `settled` is this rank's share when the run is split over ranks (its exchange).
std::optional<FillResult> move_shoe(const scene::PipelineScene& scene, const FillWalls& walls, const ShoePlan& shoe, double table_z,
                                    dem::State settled, const std::filesystem::path& dir, bool resume);

}  // namespace pipeline
