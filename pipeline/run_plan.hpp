#pragma once
// `diefill plan DIE` (docs/INTERFACE.md, "Plans"): before anything heavy runs, what each grain
// size would take on this machine and how far its fill ratio would lie from the real powder's,
// and the cheapest choice of grain size, seeds and ladder that meets a stated standard error
// within a budget. The models and their evidence are docs/PHYSICS.md §4.2's.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/preflight.hpp"
#include "scene/pipeline_scene.hpp"

namespace pipeline {

struct PlanRequest {
  double accuracy = 0.01;  // the standard error of the fill ratio asked for
  double budget_s = 1800;  // wall time on this machine
};

// One grain size.
struct PlanLevel {
  double alpha = 0, diameter_m = 0;
  RunSize size;                    // preflight's
  double grains_in_cavity = 0;     // expected, at a fill of 0.55
  double grains_across = 0;        // across the cavity's narrowest tenth (mesh/feature_width.hpp)
  double particle_steps = 0;       // of a run from a fresh shoe (three insertion rounds)
  double predicted_s = 0;          // wall time of one run
  double seed_stderr = 0;          // one seed's standard error of the fill ratio
  double bias = 0;                 // its grain size's distance from the real powder's fill ratio
  bool affine = false;             // in the range where the fill is affine in the grain size
};

// A way to the answer: one grain size with some seeds, or a ladder of three with some each.
struct PlanOption {
  std::string kind;                // "single" or "ladder"
  std::vector<double> alphas;
  int seeds = 1;                   // per level
  double predicted_s = 0, stderr_ = 0;
  bool meets_accuracy = false, within_budget = false;
  std::string command;             // the `diefill run` that does it
};

struct Plan {
  std::string die;
  PlanRequest request;
  std::string machine;             // pipeline/throughput.hpp's key
  double kernel_rate = 0;          // particle-steps per second of the kernel, this machine
  int timed_runs = 0;              // finished runs the time model is fitted to
  double narrowest_feature_m = 0;  // the width below which a tenth of the cavity lies
  std::vector<PlanLevel> levels;
  std::vector<std::pair<double, std::string>> refused;  // grain sizes the run's checks refuse, and why
  std::vector<PlanOption> options;
  std::optional<std::size_t> chosen;  // the cheapest that meets the accuracy within the budget, else the most accurate within it
};

// Plans the scene's die (refused as `diefill run` would refuse it).
Plan make_plan(const scene::PipelineScene& scene, const PlanRequest& request);
nlohmann::json plan_json(const Plan& plan);

// The plan's chosen way as `diefill run` runs it: the settings to add to the scene's (its grain
// size, a grain budget that lets the chosen sizes run, the seeds' finer voxels) and, for a
// ladder, its levels; the seeds of an ensemble or of each level.
struct PlannedRun {
  std::vector<std::string> overrides;
  std::optional<std::string> ladder;  // "A1,A2,A3"
  int seeds = 1;
};
PlannedRun planned_run(const Plan& plan, const scene::PipelineScene& scene);
std::string plan_table(const Plan& plan);

// "90", "90s", "30m", "2h", "1h30m": seconds; InputError naming --budget otherwise.
double parse_duration(const std::string& text);

}  // namespace pipeline
