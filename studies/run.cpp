// `diefill study NAME [SCENE]`: the seed study's calibration experiments on the scene's powder,
// each writing CSV tables, NAME.json and PNG charts into OUT/NAME/ (out/studies by default).
// Here rather than in cli/ so that the tests run a study as the command does.
#include <fmt/core.h>

#include <functional>
#include <map>

#include "studies/studies.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "core/timer.hpp"
#include "pipeline/run_loop.hpp"

namespace studies {

namespace {

using StudyFunction = std::function<void(const scene::PipelineScene&, bool, Output&)>;

const std::map<std::string, StudyFunction>& studies() {
  static const std::map<std::string, StudyFunction> table = {
      {"discharge", discharge},
      {"repose", repose},
      {"stability", stability},
      {"coarse-graining", coarse_graining},
      {"speed-accuracy", speed_accuracy},
      {"cross-validation", cross_validation},
      {"calibration-round-trip", calibration_round_trip}};
  return table;
}

}  // namespace

std::vector<std::string> study_names() {
  std::vector<std::string> names;
  for (const auto& [name, function] : studies()) names.push_back(name);
  return names;
}

int run_study(const StudyRequest& c) {
  const auto found = studies().find(c.name);
  if (found == studies().end()) {
    std::string known;
    for (const std::string& name : study_names()) known += (known.empty() ? "" : ", ") + name;
    throw diefill::InputError("", "NAME", fmt::format("there is no study \"{}\"", c.name), "Choose one of: " + known);
  }
  scene::PipelineScene scene = scene::load_pipeline_scene(c.scene, c.overrides);
  // The studies read fills and flows, not FEM decks or their runs' pictures: no hand-off, whose
  // mesh and CalculiX run would add seconds to each of their many runs, and no pictures (python,
  // about 1.5 s a run); the study draws its own charts.
  scene.fem.elements = scene::FemElements::none;
  scene.pictures = false;
  if (c.threads) scene.threads = *c.threads;
  if (c.seed) scene.seed = *c.seed;
  const pipeline::ThreadCount threads(scene.threads);
  diefill::Stopwatch clock;
  Output out(c.out, c.name);
  try {
    found->second(scene, c.reduced, out);
  } catch (const Interrupted&) {
    fmt::print(stderr, "interrupted; {} keeps its earlier results\n", out.directory().string());
    return diefill::exit_interrupted;
  }
  out.results["study"] = c.name;
  out.results["reduced"] = c.reduced;
  out.results["seed"] = scene.seed;
  out.results["wall_s"] = clock.seconds();
  out.commit();
  diefill::log::info("study {}: {:.0f} s -> {}", c.name, clock.seconds(), out.directory().string());
  return 0;
}

}  // namespace studies
