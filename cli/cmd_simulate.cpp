// `diefill simulate SCENE.toml`: a general DEM scene (explicit particles, walls, motions), used
// for validation experiments. Writes trajectory, snapshots, final particles and a summary.
#include <fmt/core.h>
#include <omp.h>

#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/mpi_session.hpp"
#include "pipeline/run_loop.hpp"
#include "scene/simulate_scene.hpp"
#include "core/atomic_file.hpp"
#include "core/log.hpp"
#include "dem/checkpoint.hpp"
#include "dem/distributed.hpp"
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
  const std::size_t grains = scene.state.size();
  // Under mpirun every rank reads the scene and keeps its share; rank 0 writes the outputs.
  const std::shared_ptr<dem::Exchange> ranks = mpi_exchange();
  const bool root = !ranks || ranks->rank() == 0;
  const double start_time = scene.state.time;  // where the outputs' cadence starts, resumed or not
  dem::State state = dem::share_of(std::move(scene.state), ranks);
  const fs::path checkpoint = dir / "checkpoint.bin";
  if (c.resume) {
    state = dem::read_checkpoint(model, checkpoint, ranks);
  } else {
    dem::initialize(model, state);
  }
  diefill::log::info("{}: {} grains, time step {:.3g} s (Rayleigh {:.3g} s, collision {:.3g} s), skin {:.3g} m",
                     scene.source, grains, model.dt, model.dt_rayleigh, model.dt_hertz, model.skin);

  std::unique_ptr<dem::TrajectoryWriter> trajectory;  // rank 0 opens it; should that fail, every rank stops
  dem::run_and_agree(ranks.get(), root, [&] {
    if (scene.output.trajectory) trajectory = std::make_unique<dem::TrajectoryWriter>(dir / "trajectory.csv", c.resume);
  });
  // A resumed run goes on with the interrupted one's numbering and rows instead of writing over them.
  std::int64_t snapshot =
      c.resume && scene.output.snapshot_every > 0
          ? first_output_after_resume(start_time, scene.output.snapshot_every, state.time, model.dt)
          : 0;
  LoopOptions loop;
  loop.until = scene.duration;
  loop.checkpoint = checkpoint;
  loop.resumed = c.resume;
  loop.output_origin = start_time;
  // Every rank gathers (collective); rank 0 alone holds the trajectory's file, whose rows go in id order.
  if (scene.output.trajectory)
    loop.outputs.push_back({scene.output.trajectory_every, [&](const dem::State& s) {
                              dem::with_whole_state(s, [&](const dem::State& whole) {
                                if (trajectory) trajectory->write(whole);
                              });
                            }});
  // Split over ranks, each rank writes its own grains (a .pvtu and its pieces).
  if (scene.output.snapshot_every > 0)
    loop.outputs.push_back({scene.output.snapshot_every, [&](const dem::State& s) {
                              dem::write_vtu(s, dir / fmt::format("snapshot_{:05d}.vtu", snapshot++));
                            }});
  install_interrupt_handler();
  const LoopResult result = run_until(model, state, loop);
  const std::int64_t lost = ranks ? ranks->sum(state.lost) : state.lost;
  dem::write_particles_csv(state, dir / "particles.csv");
  if (!root) return result.interrupted ? diefill::exit_interrupted : diefill::exit_ok;
  const nlohmann::json summary = {
      {"grains", grains},
      {"lost", lost},
      {"time_s", state.time},
      {"steps", state.step},
      {"dt_s", model.dt},
      {"interrupted", result.interrupted},
      {"timing",
       {{"wall_s", result.wall_s},
        {"particle_steps_per_s", double(result.steps) * double(grains) / std::max(1e-9, result.wall_s)},
        {"ranks", ranks ? ranks->ranks() : 1},
        {"threads_per_rank", omp_get_max_threads()},
        {"stages", stage_times_json(result.times)}}},
      {"stability", {{"max_overlap_rel", result.max_overlap_rel}, {"max_energy_gain", result.max_energy_gain}}}};
  diefill::write_file_atomic(dir / "summary.json", summary.dump(2) + "\n");
  if (result.interrupted) {
    fmt::print(stderr, "interrupted at t = {:.6g} s; checkpoint {} (resume with --resume)\n", state.time,
               checkpoint.string());
    return diefill::exit_interrupted;
  }
  fmt::print("{}: {} grains to t = {:.6g} s in {} steps -> {}\n", scene.source, grains, state.time,
             result.steps, dir.string());
  return 0;
}

}  // namespace app
