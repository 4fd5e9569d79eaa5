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
#include "scene/pipeline_scene.hpp"

namespace app {

struct DieRun {
  std::string die;           // name
  nlohmann::json report;     // report.json as written
  std::filesystem::path dir;
  bool interrupted = false;  // Ctrl-C: a checkpoint (or nothing, while the shoe settled) was kept
};

// Throws InputError for bad input and StabilityError when the run stops on a stability check.
// Split over MPI ranks (every rank calls it with the session's exchange), rank 0 writes the
// outputs and returns the report; the others return an empty one.
DieRun run_die_fill(const PipelineScene& scene, const std::filesystem::path& die_mesh, bool resume,
                    const std::shared_ptr<dem::Exchange>& ranks = nullptr);

}  // namespace app
