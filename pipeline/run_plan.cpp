#include "pipeline/run_plan.hpp"

#include <fmt/core.h>
#include <fmt/ranges.h>
#include <omp.h>

#include <algorithm>
#include <cctype>
#include <limits>
#include <cmath>
#include <numbers>

#include "core/error.hpp"
#include "mesh/feature_width.hpp"
#include "pipeline/extrapolate.hpp"
#include "pipeline/throughput.hpp"

namespace pipeline {

namespace fs = std::filesystem;

namespace {

// docs/PHYSICS.md §4.2: one seed's standard error of the fill ratio is 0.056/√(grains in the
// cavity) (15 seeds of the ring at 1.6 mm grains: 0.0022 with about 640 in it), a fill is about
// 0.55, and its wall layer costs λ = 0.16 grain diameters of the walls' area (the disc's ladder:
// a slope of 26.6 /m with walls of 300 /m; the ring's coarse-graining study: 43 /m with 500 /m).
constexpr double seed_noise = 0.056, typical_fill = 0.55, wall_layer = 0.16;
constexpr int fresh_rounds = 3;  // insertion rounds the default ring's shoe takes
constexpr int most_seeds = 32;

// Grain sizes √2 apart, α = 1 (the real powder) to 64, as `--set` gives them.
std::vector<double> alpha_grid() {
  std::vector<double> out;
  for (int k = 0; k <= 12; ++k) out.push_back(std::stod(fmt::format("{:.3g}", std::pow(2.0, 0.5 * k))));
  return out;
}

// The cavity's walls, its opening left out: where the wall layer lies.
double wall_area(const geometry::TriMesh& cavity, double table_z) {
  double area = 0;
  for (const auto& t : cavity.triangles) {
    const geometry::Vec3 &a = cavity.vertices[t[0]], &b = cavity.vertices[t[1]], &c = cavity.vertices[t[2]];
    const bool opening = std::min({a.z(), b.z(), c.z()}) >= table_z - 1e-9;
    if (!opening) area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

// The width below which a tenth of the cavity lies (the ladder's refusal's measure).
double narrowest_tenth(const mesh::FeatureWidths& widths) {
  std::vector<mesh::FeatureWidths::Crossing> sorted = widths.crossings;
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.width < b.width; });
  double volume = 0;
  for (const auto& c : sorted)
    if ((volume += c.volume) > thin_share_allowed * widths.cavity_volume) return c.width;
  return std::numeric_limits<double>::infinity();
}

// The fill ratio's standard error at the real powder from three levels of `seeds` seeds each.
double ladder_stderr(const std::vector<const PlanLevel*>& levels, int seeds, double target) {
  std::vector<LevelValue> points;
  for (const PlanLevel* l : levels) points.push_back({l->diameter_m, 0.5, l->seed_stderr / std::sqrt(double(seeds))});
  return fit_affine(points).stderr_at(target);
}

// One size's run; with N seeds on voxels finer by N^(1/3): one run's noise per voxel falls as
// 1/√(grains per voxel), so N seeds on voxels of 2d/N^(1/3) are as noisy as one on 2d (the
// default), and resolve features N^(1/3) times finer; the elements stay at 2d.
std::string single_command(const scene::PipelineScene& s, double alpha, double diameter, int seeds) {
  if (seeds == 1) return fmt::format("diefill run {} --set powder.coarse_graining={}", s.die.file.string(), alpha);
  return fmt::format("diefill run {} --set powder.coarse_graining={} --seeds {} --set density.voxel={:.3g} --set fem.element_size={:.3g}",
                     s.die.file.string(), alpha, seeds, 2 * diameter / std::cbrt(double(seeds)), 2 * diameter);
}

std::vector<PlanOption> options_of(const scene::PipelineScene& s, const std::vector<PlanLevel>& levels, const PlanRequest& r) {
  std::vector<PlanOption> out;
  const double a = r.accuracy, target = s.powder.particle_diameter;
  for (const PlanLevel& l : levels) {
    if (!l.affine) continue;  // its bias is not known
    PlanOption o;
    o.kind = "single", o.alphas = {l.alpha};
    if (l.bias < a) o.seeds = std::clamp(int(std::ceil(l.seed_stderr * l.seed_stderr / (a * a - l.bias * l.bias))), 1, most_seeds);
    o.stderr_ = std::hypot(l.seed_stderr / std::sqrt(double(o.seeds)), l.bias);
    o.predicted_s = o.seeds * l.predicted_s;
    o.command = single_command(s, l.alpha, l.diameter_m, o.seeds);
    out.push_back(o);
  }
  for (std::size_t k = 0; k + 2 < levels.size(); ++k) {
    const std::vector<const PlanLevel*> ladder = {&levels[k + 2], &levels[k + 1], &levels[k]};  // coarsest first
    if (!ladder.front()->affine) continue;
    PlanOption o;
    o.kind = "ladder", o.alphas = {ladder[0]->alpha, ladder[1]->alpha, ladder[2]->alpha}, o.seeds = 2;
    while (o.seeds < 8 && ladder_stderr(ladder, o.seeds, target) > a) ++o.seeds;
    o.stderr_ = ladder_stderr(ladder, o.seeds, target);
    for (const PlanLevel* l : ladder) o.predicted_s += o.seeds * l->predicted_s;
    o.command = fmt::format("diefill run {} --ladder {} --seeds {}", s.die.file.string(), fmt::join(o.alphas, ","), o.seeds);
    out.push_back(o);
  }
  for (PlanOption& o : out) o.meets_accuracy = o.stderr_ <= a, o.within_budget = o.predicted_s <= r.budget_s;
  return out;
}

std::optional<std::size_t> choose(const std::vector<PlanOption>& options) {
  std::optional<std::size_t> best;
  const auto better = [&](std::size_t k, bool by_time) {
    if (!best) return true;
    return by_time ? options[k].predicted_s < options[*best].predicted_s : options[k].stderr_ < options[*best].stderr_;
  };
  for (std::size_t k = 0; k < options.size(); ++k)
    if (options[k].meets_accuracy && options[k].within_budget && better(k, true)) best = k;
  if (best) return best;
  for (std::size_t k = 0; k < options.size(); ++k)
    if (options[k].within_budget && better(k, false)) best = k;
  return best;
}

}  // namespace

Plan make_plan(const scene::PipelineScene& scene, const PlanRequest& request) {
  if (!(request.accuracy > 0 && request.accuracy < 0.5))
    throw diefill::InputError("--accuracy", fmt::format("{}", request.accuracy), "is no standard error of a fill ratio",
                              "Give one in (0, 0.5), e.g. 0.01");
  Plan plan;
  plan.request = request;
  const DieSource die = read_die(scene.die, scene.die.file);
  plan.die = die.file.name;
  const ShoePlan shoe = plan_shoe(scene.shoe, scene.motion, die);
  const geometry::Box box = geometry::bounding_box(die.file.mesh);
  const mesh::FeatureWidths widths =
      mesh::feature_widths(die.file.mesh, die.table_z, std::max(box.size().minCoeff() / 16, std::cbrt(box.size().prod() / 5e5)));
  plan.narrowest_feature_m = narrowest_tenth(widths);
  const double volume = widths.cavity_volume, walls = wall_area(die.file.mesh, die.table_z);
  const fs::path cache = scene.output.cache.empty() ? scene.output.directory / ".cache" : scene.output.cache;
  plan.kernel_rate = kernel_rate(scene, size_grains(scene.powder, scene.shoe.fill_height, shoe, plan.die), cache);
  const TimeModel model = time_model(cache, plan.kernel_rate);
  plan.timed_runs = model.runs;
  plan.machine = machine_key(scene.threads > 0 ? scene.threads : omp_get_max_threads());
  for (const double alpha : alpha_grid()) {
    scene::PipelineScene s = scene;
    s.powder.coarse_graining = alpha;
    s.powder.max_grains = std::numeric_limits<std::size_t>::max() / 2;  // the plan sees the grains a size needs
    PlanLevel l;
    l.alpha = alpha;
    const GrainSizing grains = size_grains(s.powder, s.shoe.fill_height, shoe, plan.die);
    l.diameter_m = grains.diameter;
    l.grains_across = plan.narrowest_feature_m / grains.diameter;
    if (l.grains_across < 1) continue;  // no grain enters
    ShoePlan raised = shoe;
    set_clearance(s.shoe.clearance, grains, die.table_z, raised);
    try {
      l.size = preflight(s, die, raised, grains);
    } catch (const diefill::InputError& e) {
      plan.refused.push_back({alpha, e.what()});  // a run the checks refuse is no option
      continue;
    }
    l.particle_steps = double(l.size.grains) * double(l.size.pass_steps + fresh_rounds * l.size.settling_steps);
    l.predicted_s = model.predict(l.particle_steps, plan.kernel_rate);
    l.grains_in_cavity = typical_fill * volume / (std::numbers::pi / 6 * std::pow(l.diameter_m, 3));
    l.seed_stderr = seed_noise / std::sqrt(l.grains_in_cavity);
    l.bias = typical_fill * wall_layer * walls / volume * (l.diameter_m - scene.powder.particle_diameter);
    l.affine = l.grains_across >= grains_across_needed;
    plan.levels.push_back(l);
  }
  plan.options = options_of(scene, plan.levels, request);
  plan.chosen = choose(plan.options);
  return plan;
}

PlannedRun planned_run(const Plan& plan, const scene::PipelineScene& scene) {
  const PlanOption& chosen = plan.options.at(*plan.chosen);
  PlannedRun run;
  // The plan sized each grain size without the grain budget: the run may take what it chose.
  std::size_t grains = scene.powder.max_grains;
  for (const PlanLevel& l : plan.levels)
    if (std::find(chosen.alphas.begin(), chosen.alphas.end(), l.alpha) != chosen.alphas.end()) grains = std::max(grains, l.size.grains + 1);
  run.overrides.push_back(fmt::format("powder.max_grains={}", grains));
  run.seeds = chosen.seeds;
  if (chosen.kind == "ladder") {
    run.ladder = fmt::format("{}", fmt::join(chosen.alphas, ","));
    return run;
  }
  run.overrides.push_back(fmt::format("powder.coarse_graining={}", chosen.alphas.front()));
  if (chosen.seeds > 1) {
    // As its command says: finer voxels for the seeds (single_command).
    const double d = chosen.alphas.front() * scene.powder.particle_diameter;
    run.overrides.push_back(fmt::format("density.voxel={:.3g}", 2 * d / std::cbrt(double(chosen.seeds))));
    run.overrides.push_back(fmt::format("fem.element_size={:.3g}", 2 * d));
  }
  return run;
}

nlohmann::json plan_json(const Plan& p) {
  nlohmann::json levels = nlohmann::json::array(), options = nlohmann::json::array(), refused = nlohmann::json::array();
  for (const auto& [alpha, reason] : p.refused) refused.push_back({{"coarse_graining", alpha}, {"reason", reason}});
  for (const PlanLevel& l : p.levels)
    levels.push_back({{"coarse_graining", l.alpha}, {"grain_diameter_m", l.diameter_m}, {"grains", l.size.grains},
                      {"grains_in_cavity", l.grains_in_cavity}, {"grains_across_narrowest", l.grains_across},
                      {"pass_steps", l.size.pass_steps}, {"settling_steps_per_round", l.size.settling_steps},
                      {"particle_steps", l.particle_steps}, {"predicted_wall_s", l.predicted_s},
                      {"fill_ratio_stderr_one_seed", l.seed_stderr}, {"bias", l.bias}, {"affine", l.affine}});
  for (const PlanOption& o : p.options)
    options.push_back({{"kind", o.kind}, {"coarse_graining", o.alphas}, {"seeds", o.seeds}, {"predicted_wall_s", o.predicted_s},
                       {"predicted_stderr", o.stderr_}, {"meets_accuracy", o.meets_accuracy}, {"within_budget", o.within_budget},
                       {"command", o.command}});
  return {{"die", p.die}, {"accuracy", p.request.accuracy}, {"budget_s", p.request.budget_s},
          {"machine", {{"key", p.machine}, {"kernel_particle_steps_per_s", p.kernel_rate}, {"timed_runs", p.timed_runs}}},
          {"narrowest_tenth_m", p.narrowest_feature_m}, {"levels", levels}, {"options", options},
          {"refused_levels", refused},
          {"chosen", p.chosen ? options[*p.chosen] : nlohmann::json(nullptr)}};
}

std::string plan_table(const Plan& p) {
  std::string out = fmt::format("{}: a tenth of the cavity is narrower than {:.3g} mm; the machine's kernel runs {:.3g} "
                                "particle-steps/s ({} of its runs timed)\n\n",
                                p.die, p.narrowest_feature_m * 1e3, p.kernel_rate, p.timed_runs);
  out += "   alpha  grain [mm]     grains  across   particle-steps   predicted   1 seed's se   bias vs the powder\n";
  for (const PlanLevel& l : p.levels)
    out += fmt::format("{:8.3g}  {:10.3g} {:10} {:7.3g} {:16.3g} {:9.0f} s {:13.4f} {:10.4f}{}\n", l.alpha, l.diameter_m * 1e3,
                       l.size.grains, l.grains_across, l.particle_steps, l.predicted_s, l.seed_stderr, l.bias,
                       l.affine ? "" : "  (too few grains across)");
  for (const auto& [alpha, reason] : p.refused) out += fmt::format("{:8.3g}  refused: {}\n", alpha, reason);
  out += fmt::format("\nFor a standard error of {} within {:.0f} s:\n", p.request.accuracy, p.request.budget_s);
  for (std::size_t k = 0; k < p.options.size(); ++k) {
    const PlanOption& o = p.options[k];
    out += fmt::format("{} {:6} alpha {:<18} seeds {:2}  se {:.4f}  {:7.0f} s{}{}\n", p.chosen == k ? "->" : "  ", o.kind,
                       fmt::format("{}", fmt::join(o.alphas, ",")), o.seeds, o.stderr_, o.predicted_s,
                       o.meets_accuracy ? "" : "  (misses the accuracy)", o.within_budget ? "" : "  (over the budget)");
  }
  out += p.chosen ? "\nChosen: " + p.options[*p.chosen].command + "\n" : "\nNothing fits the budget: raise --budget\n";
  return out;
}

double parse_duration(const std::string& text) {
  double total = 0, number = 0;
  bool digits = false, any = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') {
      std::size_t used = 0;
      number = std::stod(text.substr(i), &used);
      i += used - 1, digits = true;
    } else if (digits && (c == 'h' || c == 'm' || c == 's')) {
      total += number * (c == 'h' ? 3600 : c == 'm' ? 60 : 1), digits = false, any = true;
    } else {
      throw diefill::InputError("--budget", text, "is not a duration", "Give 90, 90s, 30m, 2h or 1h30m");
    }
  }
  if (digits) total += number, any = true;
  if (!any || !(total > 0)) throw diefill::InputError("--budget", text, "is not a duration", "Give 90, 90s, 30m, 2h or 1h30m");
  return total;
}

}  // namespace pipeline
