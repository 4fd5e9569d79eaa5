// `diefill simulate SCENE.toml`: the command line's part; the run is pipeline::simulate.
#include "cli/commands.hpp"
#include "cli/mpi_session.hpp"
#include "pipeline/simulation.hpp"

namespace cli {

int run_simulate(const SimulateCommand& c) {
  scene::SimulationScene scene = scene::load_simulation_scene(c.scene, c.overrides);
  if (!c.out.empty()) scene.output.directory = c.out;
  if (c.threads) scene.threads = *c.threads;
  // Under mpirun every rank reads the scene and keeps its share; rank 0 writes the outputs.
  return pipeline::simulate(std::move(scene), c.resume, mpi_exchange());
}

}  // namespace cli
