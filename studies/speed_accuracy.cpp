// `diefill study speed-accuracy`: what each saved minute costs in accuracy. The bundled ring die
// is filled by the pipeline from nothing (SDF, shoe, pass, density) at the scene's settings (the
// reference) and with one setting changed at a time: coarser grains, softer grains, a longer time
// step, coarser wall voxels, and a few combinations. Each run's density field, on one common
// grid, is compared with the reference's; a second seed of the reference gives the noise floor
// below which a difference means nothing, and stands for the reference's own error. Charted as error against wall-clock time with the
// Pareto front, and the most accurate run within a minute, ten minutes and an hour.
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "pipeline/density_stage.hpp"
#include "pipeline/die_fill.hpp"
#include "studies/studies.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "core/timer.hpp"
#include "dem/io.hpp"
#include "mesh/die.hpp"

namespace studies {

namespace {

struct Setting {
  std::string group, label;
  double coarser = 1;         // grain size against the scene's
  double stiffness = 1;       // powder's Young's modulus against the scene's
  double time_step_fraction;  // of the collision time
  double voxel_fraction;      // die SDF voxel [largest grain radii]
  std::uint64_t seed_offset = 0;
};

std::vector<Setting> settings(const scene::PipelineScene& scene, bool reduced) {
  const double dt = scene.spec.time_step_fraction, voxel = scene.die.voxel_fraction;
  const double root2 = std::sqrt(2.0);
  std::vector<Setting> runs = {
      {"reference", "the scene's settings", 1, 1, dt, voxel},
      {"reference", "the same, another seed", 1, 1, dt, voxel, 1},
      {"coarse graining", "grains √2 coarser", root2, 1, dt, voxel},
      {"softening", "stiffness / 10", 1, 0.1, dt, voxel},
      {"time step", "time step x 2", 1, 1, 2 * dt, voxel},
      {"combined", "√2 coarser, stiffness / 10, time step x 2", root2, 0.1, 2 * dt, voxel},
  };
  if (reduced) return runs;
  const std::vector<Setting> more = {
      {"coarse graining", "grains 2x coarser", 2, 1, dt, voxel},
      {"softening", "stiffness / 3", 1, 1 / 3.0, dt, voxel},
      {"time step", "time step x 3.3", 1, 1, 3.3 * dt, voxel},
      {"voxel", "voxels x 2", 1, 1, dt, 2 * voxel},
      {"voxel", "voxels x 4", 1, 1, dt, 4 * voxel},
      {"combined", "stiffness / 10, time step x 2", 1, 0.1, 2 * dt, voxel},
      {"combined", "2x coarser, stiffness / 10, time step x 2", 2, 0.1, 2 * dt, voxel},
  };
  runs.insert(runs.end(), more.begin(), more.end());
  return runs;
}

struct RunResult {
  Setting setting;
  bool ran = false;
  std::string stopped;  // the check that stopped it
  double seconds = 0, particle_steps = 0, time_step = 0, alpha = 0, fill_ratio = 0;
  std::size_t grains = 0;
  std::vector<double> field;  // solid fraction per common voxel (NaN outside the cavity)
  double field_error = 0, fill_error = 0;
};

// Cavity-volume-weighted rms of the difference of two fields, over the reference's mean.
double field_difference(const std::vector<double>& a, const std::vector<double>& b, const std::vector<double>& cavity) {
  double weight = 0, squares = 0, mean = 0;
  for (std::size_t n = 0; n < a.size(); ++n)
    if (cavity[n] > 0 && std::isfinite(a[n]) && std::isfinite(b[n]))
      weight += cavity[n], squares += cavity[n] * (a[n] - b[n]) * (a[n] - b[n]), mean += cavity[n] * b[n];
  return std::sqrt(squares / weight) / (mean / weight);
}

// The common grid: 2 mm voxels, as coarse as the coarsest grains need and fine enough to see
// the ring's radial and vertical gradients.
constexpr double common_voxel = 2e-3;

// The bundled ring die, prepared once, and the density settings of the common grid.
struct CommonGrid {
  std::filesystem::path ring;
  mesh::PreparedDie die;
  geometry::WallField walls;
  pipeline::DensityOptions density;
};

CommonGrid common_grid(const Output& out) {
  CommonGrid grid;
  grid.ring = ring_mesh(out.work());
  grid.die = mesh::prepare_die(grid.ring, mesh::die_options_for_grains(0.5e-3, 0.25e-3), out.work() / ".cache");
  grid.walls = grid.die.sdf.wall_field(grid.die.solid);
  grid.density.voxel_m = common_voxel;
  return grid;
}

// Fills the ring at one setting and measures its density field on the common grid; `cavity`
// takes the grid's cavity fractions (the same for every run that measures one).
RunResult run_setting(const scene::PipelineScene& scene, const Setting& setting, int index, const CommonGrid& grid,
                      std::vector<double>& cavity, Output& out) {
  RunResult r;
  r.setting = setting;
  scene::PipelineScene s = scene;
  s.powder.coarse_graining *= setting.coarser;
  s.spec.materials[std::size_t(scene::powder_material(s.spec))].youngs_modulus *= setting.stiffness;
  s.spec.time_step_fraction = setting.time_step_fraction;
  s.die.voxel_fraction = setting.voxel_fraction;
  s.seed += setting.seed_offset;
  s.output.directory = out.work() / fmt::format("run_{}", index);  // its own cache: every run from nothing
  r.alpha = s.powder.coarse_graining;
  diefill::log::info("speed-accuracy: {} ({})", setting.label, setting.group);
  diefill::Stopwatch clock;
  try {
    const pipeline::DieRun run = pipeline::run_die_fill(s, grid.ring, false);
    r.seconds = clock.seconds();
    r.ran = true;
    r.fill_ratio = run.report["fill"].value("fill_ratio", 0.0);
    r.time_step = run.report["timing"].value("dt_s", 0.0);
    r.grains = run.report["powder"].value("grains", std::size_t(0));
    r.particle_steps = run.report["timing"].value("steps", 0.0) * double(r.grains);
    const double material_density = run.report["powder"].value("material_density", 0.0);
    const dem::State fill = dem::read_particles(run.dir / "particles.csv", 0, material_density);
    std::vector<post::Grain> grains;
    for (std::size_t i = 0; i < fill.size(); ++i) grains.push_back({fill.x[i], fill.radius[i], 1.0});
    const pipeline::DensityResult field = compute_density(grains, grid.die, grid.walls, material_density, grid.density, run.dir.string());
    r.field = field.field.corrected.solid_fraction;
    cavity = field.field.cavity;
  } catch (const std::runtime_error& e) {
    // A setting the checks stop or refuse is a result of the sweep (StabilityError, InputError);
    // the reference's own failure ends the study below. A stopped run still had its time step,
    // which the cost laws read.
    r.seconds = clock.seconds();
    r.stopped = e.what();
    if (const auto* stop = dynamic_cast<const diefill::StabilityError*>(&e)) r.time_step = stop->time_step_s();
    diefill::log::warn("speed-accuracy: {}: stopped: {}", setting.label, e.what());
  }
  return r;
}

// Each run's errors against the reference; returns the noise floor.
double compare_with_reference(std::vector<RunResult>& runs, const std::vector<double>& cavity, const scene::PipelineScene& scene) {
  const RunResult& reference = runs.front();
  if (!reference.ran) throw diefill::InputError(scene.source, "scene", "the reference run stopped: " + reference.stopped, "Fix the scene first");
  for (RunResult& r : runs)
    if (r.ran && &r != &reference) {
      r.field_error = field_difference(r.field, reference.field, cavity);
      r.fill_error = std::abs(r.fill_ratio / reference.fill_ratio - 1);
    }
  // A run at the reference's settings with another seed differs from it by the noise of one
  // run: the reference's own error, and the floor below which no difference means anything.
  const RunResult& replicate = runs[1];
  const double noise_floor = replicate.ran ? replicate.field_error : std::numeric_limits<double>::quiet_NaN();
  runs.front().field_error = noise_floor;
  runs.front().fill_error = replicate.fill_error;
  return noise_floor;
}

// The Pareto front: the runs no other run beats in both time and error.
struct Ranking {
  std::vector<const RunResult*> order;  // the runs that ran, but the replicate, fastest first
  std::vector<const RunResult*> front;
};

Ranking rank_runs(const std::vector<RunResult>& runs) {
  const RunResult& replicate = runs[1];
  Ranking ranking;
  std::vector<const RunResult*>& order = ranking.order;
  for (const RunResult& r : runs)
    if (r.ran && &r != &replicate) order.push_back(&r);
  std::sort(order.begin(), order.end(), [](const RunResult* a, const RunResult* b) { return a->seconds < b->seconds; });
  std::vector<const RunResult*>& front = ranking.front;
  for (const RunResult* r : order)
    if (front.empty() || r->field_error < front.back()->field_error) front.push_back(r);
  return ranking;
}

const RunResult* most_accurate_within(const std::vector<const RunResult*>& order, double budget) {
  const RunResult* best = nullptr;
  for (const RunResult* r : order)
    if (r->seconds <= budget && (!best || r->field_error < best->field_error)) best = r;
  return best;
}

// Writes speed_accuracy.csv; returns the same runs for the results.
nlohmann::json write_runs_table(const std::vector<RunResult>& runs, Output& out) {
  std::vector<std::vector<nlohmann::json>> rows;
  nlohmann::json listed = nlohmann::json::array();
  for (const RunResult& r : runs) {
    const Setting& t = r.setting;
    rows.push_back({t.group, t.label, r.alpha, t.stiffness, t.time_step_fraction, t.voxel_fraction, t.seed_offset, r.ran ? "ran" : "stopped",
                    r.seconds, r.grains, r.time_step, r.particle_steps, r.fill_ratio, r.field_error, r.fill_error});
    listed.push_back({{"group", t.group}, {"label", t.label}, {"coarse_graining", r.alpha}, {"stiffness_factor", t.stiffness},
                      {"time_step_fraction", t.time_step_fraction}, {"die_voxel_fraction", t.voxel_fraction},
                      {"seed_offset", t.seed_offset}, {"ran", r.ran}, {"stopped_by", r.stopped}, {"wall_s", r.seconds},
                      {"grains", r.grains}, {"time_step_s", r.time_step}, {"particle_steps", r.particle_steps},
                      {"fill_ratio", r.fill_ratio}, {"field_error", r.field_error}, {"fill_ratio_error", r.fill_error}});
  }
  out.table("speed_accuracy.csv",
            {"group", "setting", "coarse_graining", "stiffness_factor", "time_step_fraction", "die_voxel_fraction", "seed_offset",
             "outcome", "wall_s", "grains", "time_step_s", "particle_steps", "fill_ratio", "field_error", "fill_ratio_error"},
            rows);
  return listed;
}

void chart_error_against_time(const Ranking& ranking, double noise_floor, Output& out) {
  const std::vector<const RunResult*>& order = ranking.order;
  Chart chart{"speed_accuracy.png", "Ring die: density-field error against wall-clock time (2 cores)", "wall-clock time [s]",
              "rms error of the density field [%]"};
  chart.log_x = true;
  std::vector<std::string> groups;
  for (const RunResult* r : order)
    if (std::find(groups.begin(), groups.end(), r->setting.group) == groups.end()) groups.push_back(r->setting.group);
  for (const std::string& group : groups) {
    Series series{group, {}, {}, {}, "points"};
    for (const RunResult* r : order)
      if (r->setting.group == group) series.x.push_back(r->seconds), series.y.push_back(100 * r->field_error);
    chart.series.push_back(series);
  }
  Series pareto{"Pareto front", {}, {}, {}, "line"};
  for (const RunResult* r : ranking.front) pareto.x.push_back(r->seconds), pareto.y.push_back(100 * r->field_error);
  Series floor{"noise floor (another seed)", {order.front()->seconds, order.back()->seconds}, {100 * noise_floor, 100 * noise_floor},
               {}, "line"};
  chart.series.push_back(pareto);
  chart.series.push_back(floor);
  out.chart(chart);
}

// The most accurate run within a minute, ten minutes and an hour.
nlohmann::json budgets_json(const std::vector<const RunResult*>& order) {
  nlohmann::json budgets = nlohmann::json::array();
  for (double budget : {60.0, 600.0, 3600.0}) {
    const RunResult* best = most_accurate_within(order, budget);
    budgets.push_back({{"budget_s", budget},
                       {"setting", best ? nlohmann::json(best->setting.label) : nlohmann::json(nullptr)},
                       {"wall_s", best ? best->seconds : 0.0},
                       {"field_error", best ? best->field_error : 0.0}});
  }
  return budgets;
}

}  // namespace

void speed_accuracy(const scene::PipelineScene& scene, bool reduced, Output& out) {
  const CommonGrid grid = common_grid(out);
  std::vector<double> cavity;

  std::vector<RunResult> runs;
  int index = 0;
  for (const Setting& setting : settings(scene, reduced)) runs.push_back(run_setting(scene, setting, index++, grid, cavity, out));
  const double noise_floor = compare_with_reference(runs, cavity, scene);
  const Ranking ranking = rank_runs(runs);

  const nlohmann::json listed = write_runs_table(runs, out);
  chart_error_against_time(ranking, noise_floor, out);

  const nlohmann::json budgets = budgets_json(ranking.order);
  nlohmann::json front_labels = nlohmann::json::array();
  for (const RunResult* r : ranking.front) front_labels.push_back(r->setting.label);
  out.results = {{"common_voxel_m", common_voxel}, {"runs", listed},  {"noise_floor_field_error", noise_floor},
                 {"pareto_front", front_labels},  {"budgets", budgets}, {"reference_wall_s", runs.front().seconds}};
}

}  // namespace studies
