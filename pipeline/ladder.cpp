#include "pipeline/ladder.hpp"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "mesh/feature_width.hpp"
#include "pipeline/ensemble.hpp"
#include "pipeline/extrapolate.hpp"
#include "pipeline/pictures.hpp"
#include "postprocess/field.hpp"

namespace pipeline {

namespace fs = std::filesystem;

Ladder parse_ladder(const std::string& text) {
  Ladder ladder;
  std::stringstream list(text);
  for (std::string item; std::getline(list, item, ',');) {
    std::size_t used = 0;
    double alpha = 0;
    try {
      alpha = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != item.size() || !(alpha >= 1 && alpha <= 200))
      throw diefill::InputError("--ladder", item, "is not a coarse-graining level in [1, 200]", "Give levels like --ladder 22.6,16,11.3");
    ladder.alphas.push_back(alpha);
  }
  std::sort(ladder.alphas.begin(), ladder.alphas.end(), std::greater<>());
  ladder.alphas.erase(std::unique(ladder.alphas.begin(), ladder.alphas.end()), ladder.alphas.end());
  if (ladder.alphas.size() < 3)
    throw diefill::InputError("--ladder", text, "needs three distinct levels or more: two fix a line and leave no error",
                              "Give three levels or more, e.g. --ladder 22.6,16,11.3");
  return ladder;
}

namespace {

struct Level {
  double alpha = 0, diameter = 0;
  nlohmann::json report;  // the level's ensemble
  fs::path dir;
};

// Every level's scene: its α, the finest level's density voxels and elements (unless the scene
// gives its own), so that every level lies on one grid (grid_covering depends on the die, the
// voxel and its anchor alone), and its own folder.
scene::PipelineScene level_scene(const std::function<scene::PipelineScene(const std::vector<std::string>&)>& load, double alpha, double finest,
                          const std::vector<std::string>& more) {
  const scene::PipelineScene plain = load({});
  std::vector<std::string> overrides = {fmt::format("powder.coarse_graining={}", alpha)};
  if (plain.density.voxel == 0) overrides.push_back(fmt::format("density.voxel={}", 2 * finest));
  if (plain.fem.element_size == 0) overrides.push_back(fmt::format("fem.element_size={}", 2 * finest));
  overrides.insert(overrides.end(), more.begin(), more.end());
  scene::PipelineScene s = load(overrides);
  s.output.directory = plain.output.directory / fmt::format("powder.coarse_graining={}", alpha);
  if (s.output.cache.empty()) s.output.cache = plain.output.directory / ".cache";  // one die field and settled shoes for every level
  return s;
}

// Refusals before any run: a level the shoe's grain budget would coarsen, and features too thin.
void check_levels(const std::function<scene::PipelineScene(const std::vector<std::string>&)>& load, const Ladder& ladder, double finest) {
  for (double alpha : ladder.alphas) {
    const scene::PipelineScene s = level_scene(load, alpha, finest, {});
    const DieSource die = read_die(s.die, s.die.file);
    const GrainSizing grains = size_grains(s.powder, s.shoe.fill_height, plan_shoe(s.shoe, s.motion, die), die.file.name);
    if (std::abs(grains.alpha - alpha) > 1e-9 * alpha)
      throw diefill::InputError("--ladder", fmt::format("{}", alpha),
                                fmt::format("needs {:.0f} grains, more than powder.max_grains = {}", double(grains.count) * std::pow(grains.alpha / alpha, 3),
                                            s.powder.max_grains),
                                "Raise powder.max_grains, or give coarser levels");
  }
  const scene::PipelineScene coarsest = level_scene(load, ladder.alphas.front(), finest, {});
  const DieSource die = read_die(coarsest.die, coarsest.die.file);
  const double d = coarsest.powder.grain_diameter();
  const geometry::Box box = geometry::bounding_box(die.file.mesh);
  const double spacing = std::max(std::min(box.size().minCoeff() / 8, grains_across_needed * d / 8), std::cbrt(box.size().prod() / 5e5));
  const Refusal r = refuse_thin_features(mesh::feature_widths(die.file.mesh, die.table_z, spacing), d, coarsest.powder.particle_diameter);
  if (!r.reason.empty())
    throw diefill::InputError(die.file.source, "--ladder", r.reason,
                              fmt::format("Give a coarsest level of α = {:.2g} or less (`diefill scene` says what each level takes)", r.alpha_needed));
}

// Each level's figure at `pointer` with its pooled standard error (extrapolate.hpp).
std::vector<LevelValue> level_values(const std::vector<Level>& levels, int seeds, const std::string& pointer) {
  std::vector<LevelSpread> spreads;
  for (const Level& l : levels) {
    // A figure the level's seeds all gave alike has no _stderr beside it: its error is 0 there.
    const nlohmann::json::json_pointer error(pointer + "_stderr");
    spreads.push_back({seeds, l.report.contains(error) ? l.report.at(error).get<double>() : 0.0,
                       l.report.at("/particles/in_cavity"_json_pointer).get<double>()});
  }
  const std::vector<double> pooled = pooled_stderr(spreads);
  std::vector<LevelValue> out;
  for (std::size_t k = 0; k < levels.size(); ++k)
    out.push_back({levels[k].diameter, levels[k].report.at(nlohmann::json::json_pointer(pointer)).get<double>(), pooled[k]});
  return out;
}

nlohmann::json fit_json(const AffineFit& fit, double target) {
  return {{"fill_ratio", fit.at(target)}, {"fill_ratio_stderr", fit.stderr_at(target)}, {"slope_per_m", fit.slope},
          {"slope_stderr_per_m", std::sqrt(fit.var_slope)}, {"chi2", fit.chi2}, {"dof", fit.dof}, {"birge_factor", fit.birge},
          {"chi2_limit", chi2_quantile_99(fit.dof)}};
}

// Per voxel of the finest level's grid, the levels' mean fields fitted alike, their noise pooled
// over every voxel as grains per voxel scale it (d³), and the fill ratio's Birge factor.
std::map<std::string, post::StoredGrid> extrapolated_field(const std::vector<Level>& levels, int seeds, double target, double birge) {
  std::vector<std::map<std::string, post::StoredGrid>> fields;
  for (const Level& l : levels) fields.push_back(post::read_vdb(l.dir / "density.vdb"));
  const post::StoredGrid& finest = fields.back().at("solid_fraction");
  double constant = 0, count = 0;
  for (std::size_t k = 0; k < levels.size(); ++k)
    for (const auto& [index, se] : fields[k].at("solid_fraction_stderr").values)
      constant += se * se * seeds / std::pow(levels[k].diameter, 3), ++count;
  constant /= std::max(1.0, count);
  post::StoredGrid value{finest.voxel_m, finest.first_centre, finest.metadata, {}}, error = value;
  for (const auto& [index, phi] : finest.values) {
    std::vector<LevelValue> points;
    for (std::size_t k = 0; k < levels.size(); ++k) {
      const auto& values = fields[k].at("solid_fraction").values;
      const auto it = values.find(index);
      if (it == values.end()) break;
      points.push_back({levels[k].diameter, it->second, std::sqrt(constant * std::pow(levels[k].diameter, 3) / seeds)});
    }
    if (points.size() < levels.size()) continue;
    AffineFit fit = fit_affine(points);
    value.values[index] = fit.at(target);
    fit.var_intercept *= birge / fit.birge, fit.var_slope *= birge / fit.birge, fit.covariance *= birge / fit.birge;
    error.values[index] = fit.stderr_at(target);
  }
  value.metadata["meaning"] = "solid fraction extrapolated in the grain size";
  error.metadata["meaning"] = "standard error of extrapolated_solid_fraction";
  return {{"extrapolated_solid_fraction", value}, {"extrapolated_solid_fraction_stderr", error},
          {"cavity_fraction", fields.back().at("cavity_fraction")}};
}

// The extrapolation block and its files into `dir` (a staging folder); the reason for a refusal, or "".
std::string write_extrapolation(const std::vector<Level>& levels, const Ladder& ladder, double target_alpha, double target,
                                nlohmann::json& block, const fs::path& dir) {
  const AffineFit fit = fit_affine(level_values(levels, ladder.seeds, "/fill/fill_ratio"));
  const std::string refused = refuse_curved(fit);
  block = fit_json(fit, target);
  block["to_coarse_graining"] = target_alpha;
  block["to_grain_diameter_m"] = target;
  // Extrapolated to a coarser size than the powder's (to check the ladder against a run there),
  // the same line still answers for the real powder: said beside it.
  if (target_alpha != 1) {
    const double real = target / target_alpha;
    block["real_powder"] = {{"grain_diameter_m", real}, {"fill_ratio", fit.at(real)}, {"fill_ratio_stderr", fit.stderr_at(real)}};
  }
  block["model"] = "affine in the grain diameter (docs/PHYSICS.md §4.1)";
  block["refused"] = refused.empty() ? nlohmann::json(nullptr) : nlohmann::json(refused);
  for (const auto& [name, region] : levels.front().report.at("fill").at("regions").items()) {
    try {
      block["regions"][name] = fit_json(fit_affine(level_values(levels, ladder.seeds, "/fill/regions/" + name + "/fill_ratio")), target);
    } catch (const std::invalid_argument& e) {  // a region no seed of any level varied in
      block["regions"][name] = {{"refused", e.what()}};
    }
  }
  std::string csv = "coarse_graining,grain_diameter_m,seeds,fill_ratio,fill_ratio_stderr,grains_in_cavity,residual,folder\n";
  const std::vector<LevelValue> values = level_values(levels, ladder.seeds, "/fill/fill_ratio");
  for (std::size_t k = 0; k < levels.size(); ++k) {
    const Level& l = levels[k];
    block["levels"].push_back({{"coarse_graining", l.alpha}, {"grain_diameter_m", l.diameter}, {"fill_ratio", values[k].value},
                               {"fill_ratio_stderr", values[k].stderr_}, {"folder", l.dir.string()}});
    csv += fmt::format("{},{:.6g},{},{:.6g},{:.4g},{:.6g},{:.4g},{}\n", l.alpha, l.diameter, ladder.seeds, values[k].value,
                       values[k].stderr_, l.report.at("/particles/in_cavity"_json_pointer).get<double>(),
                       values[k].value - fit.at(l.diameter), l.dir.string());
  }
  diefill::write_file_atomic(dir / "ladder.csv", csv);
  post::write_vdb(extrapolated_field(levels, ladder.seeds, target, fit.birge), dir / "extrapolated.vdb");
  block["field"] = "extrapolated.vdb";
  diefill::write_file_atomic(dir / "ladder.json", block.dump(2) + "\n");
  draw_pictures({"ladder", (dir / "ladder.json").string()});
  return refused;
}

}  // namespace

DieRun run_ladder(const std::function<scene::PipelineScene(const std::vector<std::string>& overrides)>& load, const Ladder& ladder,
                  const std::shared_ptr<dem::Exchange>& ranks) {
  const scene::PipelineScene plain = load({});
  const double finest = ladder.alphas.back() * plain.powder.particle_diameter;
  check_levels(load, ladder, finest);
  std::vector<Level> levels;
  for (double alpha : ladder.alphas) {
    const auto level = [&](const std::vector<std::string>& more) { return level_scene(load, alpha, finest, more); };
    const DieRun run = run_ensemble(level, ladder.seeds, ranks);
    if (run.interrupted) return run;
    if (ranks && ranks->rank() != 0) continue;  // rank 0 writes
    levels.push_back({alpha, run.report.at("/powder/grain_diameter_m"_json_pointer).get<double>(), run.report, run.dir});
  }
  DieRun out;
  if (levels.empty()) return out;
  const double target_alpha = ladder.extrapolate_to.value_or(1.0);
  out.die = levels.back().report.at("/die/name"_json_pointer).get<std::string>();
  out.dir = plain.output.directory / out.die;
  out.report = levels.back().report;
  diefill::StagingFolder staging(out.dir);
  const std::string refused = write_extrapolation(levels, ladder, target_alpha, target_alpha * plain.powder.particle_diameter,
                                                  out.report["extrapolation"], staging.path());
  diefill::write_file_atomic(staging / "report.json", out.report.dump(2) + "\n");
  staging.commit();
  if (!refused.empty()) throw diefill::InputError(out.dir.string(), "extrapolation", refused, "Add a finer level, or more seeds");
  diefill::log::info("{}: fill ratio at α = {:.3g}: {:.4f} ± {:.4f} (from α = {})", out.die, target_alpha,
                     out.report["extrapolation"]["fill_ratio"].get<double>(), out.report["extrapolation"]["fill_ratio_stderr"].get<double>(),
                     fmt::format("{}", fmt::join(ladder.alphas, ", ")));
  return out;
}

}  // namespace pipeline
