// `diefill run TARGET`: the pipeline on a die mesh, on every mesh of a folder, or on a scene.
// `diefill scene [TARGET]`: the resolved scene, every default with its reason.
#include <fmt/core.h>

#include <algorithm>
#include <cctype>
#include <string_view>

#include "cli/commands.hpp"
#include "cli/mpi_session.hpp"
#include "pipeline/compare.hpp"
#include "pipeline/die_fill.hpp"
#include "pipeline/ensemble.hpp"
#include "pipeline/folder_run.hpp"
#include "pipeline/ladder.hpp"
#include "pipeline/run_plan.hpp"
#include "pipeline/sweep.hpp"
#include "pipeline/run_loop.hpp"
#include "studies/measured_powder.hpp"
#include "core/atomic_file.hpp"
#include "core/error.hpp"

namespace cli {

namespace fs = std::filesystem;

namespace {

bool is_scene(const fs::path& p) { return p.extension() == ".toml"; }

scene::PipelineScene scene_for(const fs::path& target, const std::vector<std::string>& overrides) {
  scene::PipelineScene scene = is_scene(target) ? scene::load_pipeline_scene(target, overrides) : scene::load_pipeline_scene(std::nullopt, overrides);
  if (!is_scene(target) && !target.empty()) scene.die.file = target;
  return scene;
}

void apply_command_line(scene::PipelineScene& scene, const RunCommand& c) {
  if (!c.out.empty()) scene.output.directory = c.out;
  if (c.threads) scene.threads = *c.threads;
  if (c.up) scene.die.up = mesh::parse_up(*c.up, "--up");
  if (c.units) scene.die.units = geometry::parse_unit_or_auto(*c.units, "--units");
  scene.force = c.force;
}

// A word as the shell reads it back: quoted unless it is plain.
std::string shell_word(const std::string& word) {
  const bool plain = !word.empty() && std::all_of(word.begin(), word.end(), [](unsigned char ch) {
    return std::isalnum(ch) || std::string_view("/._-=+,:@%").find(char(ch)) != std::string_view::npos;
  });
  if (plain) return word;
  std::string quoted = "'";
  for (char ch : word) quoted += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return quoted + "'";
}

// The command that resumes an interrupted run: its own arguments, the folder it wrote into (so
// that it works from any working folder) and --resume.
std::string resume_command(const RunCommand& c, const fs::path& out) {
  std::string line = "diefill run " + shell_word(c.target.string()) + " --out " + shell_word(out.string());
  for (const std::string& o : c.overrides) line += " --set " + shell_word(o);
  if (c.threads) line += fmt::format(" --threads {}", *c.threads);
  if (c.seed) line += fmt::format(" --seed {}", *c.seed);
  if (c.up) line += " --up " + shell_word(*c.up);
  if (c.units) line += " --units " + shell_word(*c.units);
  if (c.force) line += " --force";
  return line + " --resume";
}

// The scene a command's overrides and options give, with more overrides (a sweep's case, an
// ensemble's seed) after them: --seed is simulation.seed after the --set, before those.
scene::PipelineScene command_scene(const RunCommand& c, const std::vector<std::string>& more) {
  std::vector<std::string> overrides = c.overrides;
  if (c.seed) overrides.push_back(fmt::format("simulation.seed={}", *c.seed));
  overrides.insert(overrides.end(), more.begin(), more.end());
  scene::PipelineScene scene = scene_for(c.target, overrides);
  apply_command_line(scene, c);
  return scene;
}

// Ensembles and ladders run one die afresh: no folder, sweep or resume.
void refuse_beside_many_runs(const RunCommand& c, const char* option) {
  if (fs::is_directory(c.target) || c.sweep || c.resume)
    throw diefill::InputError(option, c.sweep ? "--sweep" : c.resume ? "--resume" : c.target.string(), "runs one die, afresh",
                              "Give one die mesh or scene, without --sweep or --resume");
}

int finish_many_runs(const pipeline::DieRun& run, const std::shared_ptr<dem::Exchange>& ranks) {
  const bool root = !ranks || ranks->rank() == 0;
  if (run.interrupted) {
    if (root) fmt::print(stderr, "interrupted; seed ensembles and ladders do not resume: rerun the command\n");
    return diefill::exit_interrupted;
  }
  if (root) fmt::print("{}: report {}\n", run.die, (run.dir / "report.json").string());
  return 0;
}

int run_seed_ensemble(const RunCommand& c, const std::shared_ptr<dem::Exchange>& ranks) {
  refuse_beside_many_runs(c, "--seeds");
  return finish_many_runs(pipeline::run_ensemble([&](const std::vector<std::string>& more) { return command_scene(c, more); }, *c.seeds, ranks),
                          ranks);
}

// The plan's chosen way, run as its command would run it.
int run_planned(const RunCommand& c) {
  if (fs::is_directory(c.target) || c.sweep || c.resume || c.ladder || c.seeds)
    throw diefill::InputError("--plan", "", "chooses the grain size, seeds and ladder itself", "Give --plan without --ladder, --seeds, --sweep or --resume");
  const pipeline::Plan plan = pipeline::make_plan(command_scene(c, {}), {c.accuracy, pipeline::parse_duration(c.budget)});
  fmt::print("{}", pipeline::plan_table(plan));
  if (!plan.chosen)
    throw diefill::InputError("--budget", c.budget, "fits no way to the answer", "Raise --budget (`diefill plan` lists each way's time)");
  const pipeline::PlannedRun planned = pipeline::planned_run(plan, command_scene(c, {}));
  RunCommand run = c;
  run.plan = false;
  run.overrides.insert(run.overrides.end(), planned.overrides.begin(), planned.overrides.end());
  run.ladder = planned.ladder;
  run.seeds = planned.seeds;
  return run_pipeline(run);
}

int run_grain_ladder(const RunCommand& c, const std::shared_ptr<dem::Exchange>& ranks) {
  refuse_beside_many_runs(c, "--ladder");
  pipeline::Ladder ladder = pipeline::parse_ladder(*c.ladder);
  ladder.extrapolate_to = c.extrapolate_to;
  if (c.seeds) ladder.seeds = *c.seeds;
  if (ladder.seeds < 2)
    throw diefill::InputError("--seeds", std::to_string(ladder.seeds), "a ladder's levels need two seeds or more for their errors",
                              "Give --seeds 2 or more");
  return finish_many_runs(pipeline::run_ladder([&](const std::vector<std::string>& more) { return command_scene(c, more); }, ladder, ranks),
                          ranks);
}

int run_swept(const RunCommand& c, const std::shared_ptr<dem::Exchange>& ranks) {
  const bool root = !ranks || ranks->rank() == 0;
  if (fs::is_directory(c.target))
    throw diefill::InputError(c.target.string(), "--sweep", "sweeps one die, not a folder", "Give a die mesh or a scene");
  if (c.resume)
    throw diefill::InputError("--sweep", "--resume", "a sweep does not resume", "Resume the interrupted case with `diefill run` and its --set");
  const auto load = [&](const std::vector<std::string>& more) { return command_scene(c, more); };
  const std::vector<pipeline::DieRun> runs = pipeline::run_sweep(load, pipeline::parse_sweep(*c.sweep), ranks);
  if (!runs.empty() && runs.back().interrupted) return diefill::exit_interrupted;
  if (root)
    fmt::print("sweep: {} runs; summary {}\n", runs.size(),
               (runs.front().dir.parent_path().parent_path() / ("sweep_" + pipeline::parse_sweep(*c.sweep).key + ".csv")).string());
  return 0;
}

int run_one_die(const RunCommand& c, const std::shared_ptr<dem::Exchange>& ranks) {
  const bool root = !ranks || ranks->rank() == 0;
  const scene::PipelineScene scene = command_scene(c, {});
  if (scene.die.file.empty())
    throw diefill::InputError(c.target.string(), "die.file", "names no die", "Give [die] file = \"...\" or run a mesh");
  const pipeline::DieRun run = pipeline::run_die_fill(scene, scene.die.file, c.resume, ranks);
  if (run.interrupted) {
    if (!root) return diefill::exit_interrupted;
    if (fs::exists(run.dir / "checkpoint.bin"))
      fmt::print(stderr, "interrupted; resume with `{}`{}\n", resume_command(c, scene.output.directory),
                 ranks ? " under the same mpirun" : "");
    else
      fmt::print(stderr, "interrupted before the shoe moved: no checkpoint to resume from; rerun the command to start again\n");
    return diefill::exit_interrupted;
  }
  if (root) fmt::print("{}: report {}\n", run.die, (run.dir / "report.json").string());
  return pipeline::stop_requested() ? diefill::exit_interrupted : 0;
}

}  // namespace

int run_plan(const PlanCommand& c) {
  const pipeline::Plan plan = pipeline::make_plan(command_scene(c.run, {}), {c.run.accuracy, pipeline::parse_duration(c.run.budget)});
  fmt::print("{}", pipeline::plan_table(plan));
  if (!c.json.empty()) diefill::write_file_atomic(c.json, pipeline::plan_json(plan).dump(2) + "\n");
  return 0;
}

int run_scene(const SceneCommand& c) {
  if (c.keys) {
    fmt::print("{}", scene::scene_keys_markdown());
    return 0;
  }
  if (studies::is_measured_powder(c.target) && c.overrides.empty()) {
    fmt::print("# a measured powder for `diefill calibrate`, fully resolved ({})\n{}", c.target.string(),
               studies::measured_powder_toml(studies::read_measured_powder(c.target)));
    return 0;
  }
  scene::PipelineScene scene = scene_for(c.target, c.overrides);
  scene.force = c.force;
  const std::string size = pipeline::check_before_run(scene);
  fmt::print("{}{}", scene::describe(scene), size);
  return 0;
}

int run_pipeline(const RunCommand& c) {
  pipeline::install_interrupt_handler();
  // Under mpirun every rank runs this; rank 0 reports (pipeline/die_fill.hpp).
  const std::shared_ptr<dem::Exchange> ranks = mpi_exchange();
  if (c.plan) return run_planned(c);
  if (c.ladder) return run_grain_ladder(c, ranks);
  if (c.extrapolate_to) throw diefill::InputError("--extrapolate-to", "", "extrapolates a ladder", "Give --ladder A1,A2,A3 with it");
  if (c.seeds && *c.seeds != 1) return run_seed_ensemble(c, ranks);
  if (c.sweep) return run_swept(c, ranks);
  if (!fs::is_directory(c.target)) return run_one_die(c, ranks);
  // A folder: every mesh into its own folder, then a summary table.
  RunCommand folder = c;
  folder.target.clear();  // the folder holds dies, not a scene
  return pipeline::run_folder(command_scene(folder, {}), c.target, c.resume, ranks);
}

int run_compare(const CompareCommand& c) {
  const nlohmann::json summary = pipeline::compare_runs(c.run_a, c.run_b, c.out);
  fmt::print("fill ratio {:.4f} (A) against {:.4f} (B): B - A = {:+.4f}; per voxel RMS difference {:.4f} over {} voxels -> {}\n",
             summary["fill"]["fill_ratio"]["a"].get<double>(), summary["fill"]["fill_ratio"]["b"].get<double>(),
             summary["fill"]["fill_ratio"]["difference"].get<double>(), summary["field"]["rms_difference"].get<double>(),
             summary["field"]["voxels"].get<std::size_t>(), c.out.string());
  return 0;
}

}  // namespace cli
