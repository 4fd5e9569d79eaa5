#pragma once
// The die-filling workflow for one die, as a list of stages (each in its own file, testable
// alone): read the die, plan the shoe and size the grains, prepare the walls, fill and settle the
// shoe (cached), move it over the die and let the die settle, count every grain, and write the
// density field, the report and the pictures into OUT/<die name>/ (docs/INTERFACE.md).
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "dem/exchange.hpp"
#include "pipeline/fill_curve.hpp"
#include "pipeline/walls.hpp"
#include "postprocess/density.hpp"
#include "scene/pipeline_scene.hpp"

namespace pipeline {

struct DieRun {
  std::string die;           // name
  nlohmann::json report;     // report.json as written
  std::filesystem::path dir;
  bool interrupted = false;  // Ctrl-C: a checkpoint (or nothing, while the shoe settled) was kept
  // What a seed ensemble combines (pipeline/ensemble.hpp): the grains in the cavity at the end,
  // as they were binned, and the fill curve (rank 0's; empty on the others).
  std::vector<post::Grain> cavity_grains;
  std::vector<FillSample> fill_curve;
};

// The stages before any grain: the die read, the shoe planned, the grains sized, the run's size
// checked (pipeline/preflight.hpp) and the walls prepared (from the cache when it holds them).
struct FillSetup {
  DieSource source;
  ShoePlan shoe;
  GrainSizing grains;
  FillWalls walls;
};
// Every check a run makes before its first step but those that need the die's distance field
// (its repair, whether grains enter the cavity), which the run builds and caches; returns the
// run's size described (`diefill scene`), empty when the scene names no die.
std::string check_before_run(const scene::PipelineScene& scene);

FillSetup set_up_fill(const scene::PipelineScene& scene, const std::filesystem::path& die_mesh,
                      const std::shared_ptr<dem::Exchange>& ranks = nullptr);

// Throws InputError for bad input and StabilityError when the run stops on a stability check.
// Split over MPI ranks (every rank calls it with the session's exchange), rank 0 writes the
// outputs and returns the report; the others return an empty one.
DieRun run_die_fill(const scene::PipelineScene& scene, const std::filesystem::path& die_mesh, bool resume,
                    const std::shared_ptr<dem::Exchange>& ranks = nullptr);

}  // namespace pipeline
