#pragma once
// The outputs of a die fill, written together or not at all into OUT/<die>/ (docs/INTERFACE.md,
// "Outputs"): the density field and its pictures, the grains (CSV, VTU), the resolved scene and
// report.json.
#include <filesystem>
#include <nlohmann/json.hpp>

#include "pipeline/census.hpp"
#include "pipeline/shoe_fill.hpp"
#include "pipeline/shoe_pass.hpp"

namespace app {

// What the outputs are made of.
struct FillRecord {
  const PipelineScene& scene;
  const FillWalls& walls;
  const GrainSizing& grains;
  const ShoePlan& shoe;
  const SettledShoe& settled;
  const FillResult& fill;
  const Census& census;
  double table_z;
  double wall_s;  // the whole run's wall-clock time so far
  int ranks;      // MPI ranks the run was split over (1: one process)
};

// Writes every output into `dir` (staged: a failure keeps the earlier outputs); returns the report.
nlohmann::json write_fill_outputs(const FillRecord& record, const std::filesystem::path& dir);

}  // namespace app
