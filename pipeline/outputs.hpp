#pragma once
// The outputs of a die fill, written together or not at all into OUT/<die>/ (docs/INTERFACE.md,
// "Outputs"): the density field and its pictures, the grains (CSV, VTU), the resolved scene and
// report.json.
#include <filesystem>
#include <nlohmann/json.hpp>

#include "pipeline/census.hpp"
#include "pipeline/fill_curve.hpp"
#include "pipeline/shoe_fill.hpp"
#include "pipeline/shoe_pass.hpp"

namespace pipeline {

// What the outputs are made of.
struct FillRecord {
  const scene::PipelineScene& scene;
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

// What one run's field, fill curve and FEM hand-off are made of, or a seed ensemble's (one entry
// per seed): the grains in the cavity and the fill curve.
struct Realisations {
  std::vector<std::vector<post::Grain>> cavity;
  std::vector<std::vector<FillSample>> curves;
};
// What the realisations share.
struct FillSetting {
  const scene::PipelineScene& scene;
  const FillWalls& walls;
  const GrainSizing& grains;
  const ShoePlan& shoe;
};
struct FillProducts {
  nlohmann::json fill, fem;  // the report's sections
};
// The density field and its pictures, the fill curve and the FEM hand-off, into `dir`: one run's,
// or an ensemble's means with their standard errors (pipeline/ensemble.hpp).
FillProducts write_fill_products(const FillSetting& setting, const Realisations& realisations, const std::filesystem::path& dir);

// The report's hash of the scene's shaping keys and materials, the seed left out: seeds of one
// scene hash alike (`diefill compare`, the ensemble's check that its runs belong together).
std::string scene_hash(const scene::PipelineScene& scene);

}  // namespace pipeline
