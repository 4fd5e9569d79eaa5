#include "pipeline/shoe_pass.hpp"

#include <fmt/core.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "dem/checkpoint.hpp"
#include "dem/distributed.hpp"
#include "dem/io.hpp"
#include "dem/step.hpp"
#include "mesh/import.hpp"

namespace pipeline {

namespace fs = std::filesystem;

namespace {

// The shoe's surface in its own frame (the pose at a time is its motion's position).
geometry::TriMesh surface_of(const geometry::WallField& field) {
  geometry::TriMesh m;
  m.vertices = field.vertices;
  m.triangles = field.triangles;
  return m;
}

// `series.pvd`: ParaView opens the snapshots as one time series, with the die (fixed) and the
// shoe at each snapshot's pose beside the grains.
void write_series(const geometry::TriMesh& die_solid, const std::vector<double>& times, const fs::path& dir) {
  mesh::write_vtp(die_solid, dir / "die.vtp");
  std::string pvd = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
  for (std::size_t k = 0; k < times.size(); ++k)
    pvd += fmt::format("<DataSet timestep=\"{:.9g}\" part=\"0\" file=\"snapshot_{:05d}.vtu\"/>\n"
                       "<DataSet timestep=\"{:.9g}\" part=\"1\" file=\"die.vtp\"/>\n"
                       "<DataSet timestep=\"{:.9g}\" part=\"2\" file=\"shoe_{:05d}.vtp\"/>\n",
                       times[k], k, times[k], times[k], k);
  pvd += "</Collection>\n</VTKFile>\n";
  diefill::write_file_atomic(dir / "series.pvd", pvd);
}

// What the outputs of an interrupted fill wrote before its checkpoint (beside it, as
// checkpoint_outputs.json): the cadence's origin, the fill curve's samples and the snapshots'
// times, so that the resumed run's fill curve and series are the uninterrupted run's; and the
// seed, which the checkpoint's model hash does not hold, so that a resume under another seed
// cannot report that seed for this run's grains.
struct OutputsSoFar {
  double origin = 0;  // [s]
  std::vector<FillSample> curve;
  std::vector<double> snapshot_times;  // [s]
};

fs::path outputs_file(const fs::path& checkpoint) { return checkpoint.parent_path() / "checkpoint_outputs.json"; }

void save_outputs(double origin, const std::vector<FillSample>& fill_curve, const std::vector<double>& snapshot_times,
                  std::uint64_t seed, const fs::path& checkpoint) {
  nlohmann::json curve = nlohmann::json::array();
  for (const FillSample& p : fill_curve) curve.push_back({p.time, p.shoe_x, p.grains, p.mass});
  const nlohmann::json j = {{"origin_s", origin}, {"fill_curve", curve}, {"snapshot_times_s", snapshot_times}, {"seed", seed}};
  diefill::write_file_atomic(outputs_file(checkpoint), j.dump() + "\n");
}

// A checkpoint without that file beside it (deleted) resumes with the outputs from the
// resumption on; said so.
OutputsSoFar load_outputs(const fs::path& checkpoint, double origin, std::uint64_t seed) {
  const fs::path file = outputs_file(checkpoint);
  if (!fs::exists(file)) {
    diefill::log::warn("{}: not found: the fill curve and the snapshot series start where the run resumes", file.string());
    return {origin, {}, {}};
  }
  try {
    std::ifstream in(file);
    const nlohmann::json j = nlohmann::json::parse(in);
    if (j.contains("seed") && j.at("seed").get<std::uint64_t>() != seed)
      throw diefill::InputError(checkpoint.string(), "simulation.seed",
                                fmt::format("was written by a run of seed {}, not {}", j.at("seed").get<std::uint64_t>(), seed),
                                fmt::format("Resume with --seed {}, or run without --resume to start afresh", j.at("seed").get<std::uint64_t>()));
    OutputsSoFar o{j.at("origin_s").get<double>(), {}, j.at("snapshot_times_s").get<std::vector<double>>()};
    for (const auto& p : j.at("fill_curve"))
      o.curve.push_back({p.at(0).get<double>(), p.at(1).get<double>(), p.at(2).get<std::int64_t>(), p.at(3).get<double>()});
    return o;
  } catch (const nlohmann::json::exception& e) {
    throw diefill::InputError(file.string(), "", fmt::format("is not what an interrupted run leaves ({})", e.what()),
                              "Delete it to resume without the outputs written before the interrupt");
  }
}

}  // namespace

std::optional<FillResult> move_shoe(const scene::PipelineScene& s, const FillWalls& walls, const ShoePlan& shoe, double table_z,
                                    dem::State settled, const fs::path& dir, bool resume) {
  dem::ModelSpec spec = walls.spec;
  spec.meshes[walls.shoe_wall].motion = shoe.motion;
  FillResult fill{std::move(settled), {}, 0, {}};
  dem::State& state = fill.state;
  const dem::Model model = dem::compile_model(spec, state, s.source);
  fill.dt = model.dt;
  const fs::path checkpoint = dir / "checkpoint.bin";
  OutputsSoFar so_far{state.time, {}, {}};
  const bool resumed = start_or_resume(model, state, checkpoint, resume, walls.die.name,
                                       [&] { so_far = load_outputs(checkpoint, state.time, s.seed); });
  fill.curve = std::move(so_far.curve);
  std::vector<double>& snapshot_times = so_far.snapshot_times;
  const geometry::TriMesh shoe_surface = surface_of(*walls.shoe_field);
  LoopOptions loop;
  loop.until = shoe.t_motion + s.motion.die_settle_time;
  loop.max_steps = s.max_steps;
  loop.label = walls.die.name + ": filling";
  loop.checkpoint = checkpoint;
  loop.resumed = resumed;
  loop.output_origin = so_far.origin;
  if (s.output.snapshot_every > 0)
    loop.outputs.push_back({s.output.snapshot_every, [&](const dem::State& st) {
                              const std::size_t k = snapshot_times.size();
                              snapshot_times.push_back(st.time);
                              dem::with_whole_state(st, [&](const dem::State& whole) {
                                dem::write_vtu(whole, dir / fmt::format("snapshot_{:05d}.vtu", k));
                                mesh::write_vtp(shoe_surface, dir / fmt::format("shoe_{:05d}.vtp", k), shoe.motion.position(st.time));
                              });
                            }});
  const double density = walls.spec.materials[std::size_t(walls.powder)].density;
  loop.outputs.push_back({s.output.fill_curve_every, [&](const dem::State& st) { fill.curve.push_back(sample_fill(st, table_z, density, shoe)); }});
  loop.detail = [&](const dem::State& st) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < st.owned(); ++i) n += st.active[i] && st.body[i] < 0 && st.x[i].z() < table_z;
    for (std::size_t b = 0; b < st.bodies.size(); ++b) n += st.bodies.active[b] && st.bodies.x[b].z() < table_z;
    return fmt::format("{} grains in the cavity", st.exchange ? std::size_t(st.exchange->sum(std::int64_t(n))) : n);
  };
  const auto keep_outputs = [&] {
    if (dem::writes_outputs(state)) save_outputs(so_far.origin, fill.curve, snapshot_times, s.seed, checkpoint);
  };
  try {
    fill.loop = run_until(model, state, loop);
  } catch (const diefill::StabilityError&) {
    keep_outputs();
    throw;
  }
  if (fill.loop.interrupted) {
    keep_outputs();
    return std::nullopt;
  }
  if (!snapshot_times.empty() && dem::writes_outputs(state)) write_series(walls.die.solid, snapshot_times, dir);
  if (dem::writes_outputs(state)) dem::remove_checkpoint(checkpoint), fs::remove(outputs_file(checkpoint));
  // The outputs are written from the whole state, on rank 0 of a split run.
  if (state.exchange) state = dem::gathered(state);
  return fill;
}

}  // namespace pipeline
