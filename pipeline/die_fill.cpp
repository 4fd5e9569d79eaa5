#include "pipeline/die_fill.hpp"

#include <omp.h>

#include "core/error.hpp"
#include "core/log.hpp"
#include "core/timer.hpp"
#include "dem/distributed.hpp"
#include "pipeline/census.hpp"
#include "pipeline/outputs.hpp"
#include "pipeline/plan.hpp"
#include "pipeline/preflight.hpp"
#include "pipeline/run_loop.hpp"
#include "pipeline/shoe_fill.hpp"
#include "pipeline/shoe_pass.hpp"
#include "pipeline/throughput.hpp"
#include "pipeline/walls.hpp"

namespace pipeline {

namespace fs = std::filesystem;

namespace {


// Split over ranks, rank 0 prepares the walls first (building the fields into the cache) and the
// others then read them from it; a failure on any rank stops every rank.
FillWalls walls_rank0_first(const scene::PipelineScene& s, const DieSource& source, const GrainSizing& grains, const ShoePlan& shoe,
                            const std::shared_ptr<dem::Exchange>& ranks) {
  if (!ranks || ranks->ranks() == 1) return prepare_walls(s, source, grains, shoe);
  FillWalls walls;
  const auto prepare = [&] { walls = prepare_walls(s, source, grains, shoe); };
  const bool first = ranks->rank() == 0;
  dem::run_and_agree(ranks.get(), first, prepare);
  dem::run_and_agree(ranks.get(), !first, prepare);
  return walls;
}

}  // namespace

std::string check_before_run(const scene::PipelineScene& s) {
  preflight_laws(s);
  if (s.die.file.empty()) return {};
  const auto [source, shoe, grains] = lay_out_fill(s, s.die.file);
  const RunSize size = preflight(s, source, shoe, grains);
  refuse_oversized(s, size, source.file.source);
  return describe_size(size, source.file.name);
}

FillSetup set_up_fill(const scene::PipelineScene& s, const fs::path& die_mesh, const std::shared_ptr<dem::Exchange>& ranks) {
  auto [source, shoe, grains] = lay_out_fill(s, die_mesh);
  refuse_oversized(s, preflight(s, source, shoe, grains), source.file.source);
  FillWalls walls = walls_rank0_first(s, source, grains, shoe, ranks);
  return {std::move(source), std::move(shoe), grains, std::move(walls)};
}

DieRun run_die_fill(const scene::PipelineScene& s, const fs::path& die_mesh, bool resume, const std::shared_ptr<dem::Exchange>& ranks) {
  diefill::Stopwatch clock;
  const ThreadCount threads(s.threads);
  if (s.max_steps > 0)
    diefill::log::warn("a smoke run: every DEM stage ends after at most {} steps; its outputs are no fill", s.max_steps);
  const FillSetup setup = set_up_fill(s, die_mesh, ranks);
  const auto& [source, shoe, grains, walls] = setup;
  DieRun run;
  run.die = walls.die.name;
  run.dir = s.output.directory / run.die;
  fs::create_directories(run.dir);

  const std::optional<SettledShoe> settled = fill_and_settle_shoe(s, walls, grains, shoe, source.table_z, ranks);
  if (!settled) {
    run.interrupted = true;
    return run;
  }
  const std::optional<FillResult> fill = move_shoe(s, walls, shoe, source.table_z, settled->state, run.dir, resume);
  if (!fill) {
    run.interrupted = true;
    return run;
  }
  if (ranks && ranks->rank() != 0) return run;  // rank 0 counts and writes

  const Census census = count_grains(fill->state, settled->inserted, source.table_z, shoe, walls.spec.domain);
  check_losses(census, source.file.source, walls.die.name);
  const FillRecord record{s, walls, grains, shoe, *settled, *fill, census, source.table_z, clock.seconds(), ranks ? ranks->ranks() : 1};
  run.report = write_fill_outputs(record, run.dir);
  if (!ranks || ranks->ranks() == 1)  // the plan's model is one process's
    record_timing(walls.cache, settled->particle_steps + double(fill->loop.steps) * double(fill->state.size()), clock.seconds(),
                  omp_get_max_threads());
  run.cavity_grains = census.cavity;
  run.fill_curve = fill->curve;
  return run;
}

}  // namespace pipeline
