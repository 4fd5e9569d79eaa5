#include "pipeline/shoe_pass.hpp"

#include <fmt/core.h>

#include "core/log.hpp"
#include "dem/checkpoint.hpp"
#include "dem/distributed.hpp"
#include "dem/io.hpp"
#include "dem/step.hpp"

namespace app {

namespace fs = std::filesystem;

std::optional<FillResult> move_shoe(const PipelineScene& s, const FillWalls& walls, const ShoePlan& shoe, double table_z,
                                    dem::State settled, const fs::path& dir, bool resume) {
  dem::ModelSpec spec = walls.spec;
  spec.meshes[1].motion = shoe.motion;
  FillResult fill{std::move(settled), {}, 0, {}};
  dem::State& state = fill.state;
  const dem::Model model = dem::compile_model(spec, state, s.source);
  fill.dt = model.dt;
  const fs::path checkpoint = dir / "checkpoint.bin";
  // Split over ranks, rank 0 looks for the checkpoint and every rank goes by what it saw.
  const bool found = state.exchange ? state.exchange->max(state.exchange->rank() == 0 && fs::exists(checkpoint) ? 1.0 : 0.0) > 0
                                    : fs::exists(checkpoint);
  if (resume && found) {
    state = dem::read_checkpoint(model, checkpoint, state.exchange);
    diefill::log::info("{}: resumed at t = {:.6g} s", walls.die.name, state.time);
  } else {
    dem::initialize(model, state);
  }
  LoopOptions loop;
  loop.until = shoe.t_motion + s.die_settle_time;
  loop.label = walls.die.name + ": filling";
  loop.checkpoint = checkpoint;
  int snapshot = 0;
  if (s.snapshot_every > 0)
    loop.outputs.push_back({s.snapshot_every, [&](const dem::State& st) {
                              const fs::path file = dir / fmt::format("snapshot_{:05d}.vtu", snapshot++);
                              dem::with_whole_state(st, [&](const dem::State& whole) { dem::write_vtu(whole, file); });
                            }});
  const double density = walls.spec.materials[std::size_t(walls.powder)].density;
  loop.outputs.push_back({s.fill_curve_every, [&](const dem::State& st) { fill.curve.push_back(sample_fill(st, table_z, density, shoe)); }});
  loop.detail = [&](const dem::State& st) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < st.owned(); ++i) n += st.active[i] && st.body[i] < 0 && st.x[i].z() < table_z;
    for (std::size_t b = 0; b < st.bodies.size(); ++b) n += st.bodies.active[b] && st.bodies.x[b].z() < table_z;
    return fmt::format("{} grains in the cavity", st.exchange ? std::size_t(st.exchange->sum(std::int64_t(n))) : n);
  };
  fill.loop = run_until(model, state, loop);
  if (fill.loop.interrupted) return std::nullopt;
  if (dem::writes_outputs(state)) fs::remove(checkpoint);
  // The outputs are written from the whole state, on rank 0 of a split run.
  if (state.exchange) state = dem::gathered(state);
  return fill;
}

}  // namespace app
