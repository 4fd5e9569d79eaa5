#pragma once
// `diefill run FOLDER`: every die mesh of a folder, each into its own folder, then a summary.
#include <filesystem>
#include <memory>

#include "dem/exchange.hpp"
#include "scene/pipeline_scene.hpp"

namespace pipeline {

// Runs the scene on each mesh file of `folder` (others are passed over, with a note), a refused or
// stopped die not stopping the next; writes summary.csv and summary.md into the scene's output
// folder. Returns the exit status: 3 if a die was stopped, else 2 if one was refused, else 0
// (130 when interrupted).
int run_folder(const scene::PipelineScene& scene, const std::filesystem::path& folder, bool resume,
               const std::shared_ptr<dem::Exchange>& ranks);

}  // namespace pipeline
