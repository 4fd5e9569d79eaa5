#pragma once
// The die-filling workflow for one die: build or reuse the die's SDF; fill the shoe with powder
// and let it settle (cached, reused by runs that differ only in kinematics); move the shoe over
// the die; let the die settle; count every grain; compute the density field; write the
// outputs of INTERFACE.md into OUT/<die name>/.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "app/pipeline_scene.hpp"

namespace app {

struct DieRun {
  std::string die;           // name
  nlohmann::json report;     // report.json as written
  std::filesystem::path dir;
  bool interrupted = false;
};

// Throws InputError for bad input and StabilityError when the run stops on a stability check.
DieRun run_die_fill(const PipelineScene& scene, const std::filesystem::path& die_mesh, bool resume);

}  // namespace app
