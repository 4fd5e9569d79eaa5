#include "pipeline/simulation.hpp"

#include <fmt/core.h>
#include <omp.h>

#include <nlohmann/json.hpp>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "dem/distributed.hpp"
#include "dem/io.hpp"
#include "mesh/die.hpp"
#include "pipeline/run_loop.hpp"

namespace pipeline {

namespace fs = std::filesystem;

namespace {

// summary.json: the run's size, its time and steps, its speed and its stability.
nlohmann::json summary_json(const dem::Model& model, const dem::State& state, const LoopResult& result, std::size_t grains,
                            std::int64_t lost, int ranks) {
  return {{"grains", grains},
          {"lost", lost},
          {"time_s", state.time},
          {"steps", state.step},
          {"dt_s", model.dt},
          {"interrupted", result.interrupted},
          {"timing",
           {{"wall_s", result.wall_s},
            {"particle_steps_per_s", double(result.steps) * double(grains) / std::max(1e-9, result.wall_s)},
            {"ranks", ranks},
            {"threads_per_rank", omp_get_max_threads()},
            {"stages", stage_times_json(result.times)}}},
          {"stability", {{"max_overlap_rel", result.max_overlap_rel}, {"max_energy_gain", result.max_energy_gain}}}};
}

// The scene's mesh walls, their fields built here: loading the scene builds nothing heavy.
void add_mesh_walls(scene::SimulationScene& scene) {
  double r_max = 0;
  for (double r : scene.state.radius) r_max = std::max(r_max, r);
  for (const scene::MeshWallEntry& w : scene.mesh_walls) {
    mesh::DieOptions options = mesh::die_options_for_grains(r_max, scene.spec.skin.value_or(0.5 * r_max));
    options.unit = geometry::parse_unit(w.units, w.name + ".units");
    options.role = mesh::parse_role(w.role, w.name + ".role");
    const mesh::PreparedDie die = mesh::prepare_die(w.file, options, std::nullopt);
    dem::MeshWall wall =
        dem::fixed_mesh_wall(std::make_shared<const geometry::WallField>(die.sdf.wall_field(die.solid)), w.material, w.name);
    if (w.motion) wall.motion = *w.motion;
    scene.spec.meshes.push_back(wall);
  }
}

}  // namespace

int simulate(scene::SimulationScene scene, bool resume, const std::shared_ptr<dem::Exchange>& ranks) {
  const ThreadCount threads(scene.threads);
  const fs::path dir = scene.output.directory;
  add_mesh_walls(scene);
  fs::create_directories(dir);
  const dem::Model model = dem::compile_model(scene.spec, scene.state, scene.source);
  const std::size_t grains = scene.state.size();
  const bool root = !ranks || ranks->rank() == 0;
  const double start_time = scene.state.time;  // where the outputs' cadence starts, resumed or not
  dem::State state = dem::share_of(std::move(scene.state), ranks);
  const fs::path checkpoint = dir / "checkpoint.bin";
  const bool resumed = start_or_resume(model, state, checkpoint, resume, scene.source);
  diefill::log::info("{}: {} grains, time step {:.3g} s (Rayleigh {:.3g} s, collision {:.3g} s), skin {:.3g} m",
                     scene.source, grains, model.dt, model.dt_rayleigh, model.dt_hertz, model.skin);

  std::unique_ptr<dem::TrajectoryWriter> trajectory;  // rank 0 opens it; should that fail, every rank stops
  dem::run_and_agree(ranks.get(), root, [&] {
    if (scene.output.trajectory) trajectory = std::make_unique<dem::TrajectoryWriter>(dir / "trajectory.csv", resumed);
  });
  // A resumed run goes on with the interrupted one's numbering and rows instead of writing over them.
  std::int64_t snapshot =
      resumed && scene.output.snapshot_every > 0
          ? first_output_after_resume(start_time, scene.output.snapshot_every, state.time, model.dt)
          : 0;
  LoopOptions loop;
  loop.until = scene.duration;
  loop.checkpoint = checkpoint;
  loop.resumed = resumed;
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
  diefill::write_file_atomic(dir / "summary.json",
                             summary_json(model, state, result, grains, lost, ranks ? ranks->ranks() : 1).dump(2) + "\n");
  if (result.interrupted) {
    fmt::print(stderr, "interrupted at t = {:.6g} s; checkpoint {} (resume with --resume)\n", state.time, checkpoint.string());
    return diefill::exit_interrupted;
  }
  fmt::print("{}: {} grains to t = {:.6g} s in {} steps -> {}\n", scene.source, grains, state.time, result.steps, dir.string());
  return 0;
}

}  // namespace pipeline
