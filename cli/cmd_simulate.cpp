// `diefill simulate SCENE.toml`: a general DEM scene (explicit particles, walls, motions), used
// for validation experiments. Writes trajectory, snapshots, final particles and a summary.
#include <fmt/core.h>
#include <omp.h>

#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "pipeline/run_loop.hpp"
#include "scene/simulate_scene.hpp"
#include "core/atomic_file.hpp"
#include "core/log.hpp"
#include "dem/checkpoint.hpp"
#include "dem/io.hpp"

namespace app {

namespace fs = std::filesystem;

int run_simulate(const SimulateCommand& c) {
  SimulationScene scene = load_simulation_scene(c.scene, c.overrides);
  if (!c.out.empty()) scene.output.directory = c.out;
  if (c.threads) scene.threads = *c.threads;
  if (scene.threads > 0) omp_set_num_threads(scene.threads);
  const fs::path dir = scene.output.directory;
  fs::create_directories(dir);
  const dem::Model model = dem::compile_model(scene.spec, scene.state, scene.source);
  dem::State state = std::move(scene.state);
  const fs::path checkpoint = dir / "checkpoint.bin";
  if (c.resume) {
    state = dem::read_checkpoint(model, checkpoint);
  } else {
    dem::initialize(model, state);
  }
  diefill::log::info("{}: {} grains, time step {:.3g} s (Rayleigh {:.3g} s, collision {:.3g} s), skin {:.3g} m",
                     scene.source, state.size(), model.dt, model.dt_rayleigh, model.dt_hertz, model.skin);

  std::unique_ptr<dem::TrajectoryWriter> trajectory;
  if (scene.output.trajectory) trajectory = std::make_unique<dem::TrajectoryWriter>(dir / "trajectory.csv");
  int snapshot = 0;
  double next_snapshot = scene.output.snapshot_every > 0 ? state.time : std::numeric_limits<double>::infinity();
  LoopOptions loop;
  loop.until = scene.duration;
  loop.checkpoint = checkpoint;
  loop.output_every = scene.output.trajectory ? scene.output.trajectory_every
                                              : (scene.output.snapshot_every > 0 ? scene.output.snapshot_every : 0);
  if (scene.output.trajectory && scene.output.snapshot_every > 0)
    loop.output_every = std::min(scene.output.trajectory_every, scene.output.snapshot_every);
  loop.output = [&](const dem::State& s) {
    if (trajectory) trajectory->write(s);
    if (s.time >= next_snapshot - 0.5 * model.dt) {
      dem::write_vtu(s, dir / fmt::format("snapshot_{:05d}.vtu", snapshot++));
      next_snapshot += scene.output.snapshot_every;
    }
  };
  install_interrupt_handler();
  const LoopResult result = run_until(model, state, loop);
  dem::write_particles_csv(state, dir / "particles.csv");
  const nlohmann::json summary = {
      {"grains", state.size()},
      {"lost", state.lost},
      {"time_s", state.time},
      {"steps", state.step},
      {"dt_s", model.dt},
      {"interrupted", result.interrupted},
      {"timing",
       {{"wall_s", result.wall_s},
        {"particle_steps_per_s", double(result.steps) * double(state.size()) / std::max(1e-9, result.wall_s)},
        {"stages", stage_times_json(result.times)}}},
      {"stability", {{"max_overlap_rel", result.max_overlap_rel}, {"max_energy_gain", result.max_energy_gain}}}};
  diefill::write_file_atomic(dir / "summary.json", summary.dump(2) + "\n");
  if (result.interrupted) {
    fmt::print(stderr, "interrupted at t = {:.6g} s; checkpoint {} (resume with --resume)\n", state.time,
               checkpoint.string());
    return diefill::exit_interrupted;
  }
  fmt::print("{}: {} grains to t = {:.6g} s in {} steps -> {}\n", scene.source, state.size(), state.time,
             result.steps, dir.string());
  return 0;
}

}  // namespace app
