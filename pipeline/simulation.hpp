#pragma once
// `diefill simulate`: a general DEM scene (explicit particles, walls, motions), used for validation
// experiments, stepped by the loop every command shares (run_loop.hpp). Writes the trajectory,
// snapshots, final particles and a summary into the scene's output folder.
#include <memory>

#include "dem/exchange.hpp"
#include "scene/simulate_scene.hpp"

namespace pipeline {

// Runs the scene to its duration, from the folder's checkpoint when `resume`; under mpirun
// (`ranks`) every rank keeps its share and rank 0 writes the outputs. Returns the exit status.
int simulate(scene::SimulationScene scene, bool resume, const std::shared_ptr<dem::Exchange>& ranks);

}  // namespace pipeline
