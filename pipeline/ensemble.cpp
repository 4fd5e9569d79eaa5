#include "pipeline/ensemble.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <optional>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "core/sha256.hpp"
#include "core/timer.hpp"
#include "dem/distributed.hpp"
#include "pipeline/fem_stage.hpp"
#include "pipeline/outputs.hpp"
#include "pipeline/sweep.hpp"
#include "postprocess/ensemble_stats.hpp"

namespace pipeline {

namespace fs = std::filesystem;

namespace {

// Each block's number, or array of numbers (all of one length), as samples; none for anything else.
std::optional<std::vector<std::vector<double>>> numeric_samples(const std::vector<nlohmann::json>& blocks) {
  std::vector<std::vector<double>> samples;
  for (const nlohmann::json& b : blocks) {
    if (b.is_number()) samples.push_back({b.get<double>()});
    else if (b.is_array() && !b.empty() && std::all_of(b.begin(), b.end(), [](const auto& x) { return x.is_number(); }))
      samples.push_back(b.get<std::vector<double>>());
    else return std::nullopt;
    if (samples.back().size() != samples.front().size() || b.is_number() != blocks.front().is_number()) return std::nullopt;
  }
  return samples;
}

nlohmann::json as_first(const nlohmann::json& first, const std::vector<double>& values) {
  return first.is_number() ? nlohmann::json(values.front()) : nlohmann::json(values);
}

}  // namespace

nlohmann::json mean_with_stderr(const std::vector<nlohmann::json>& blocks) {
  const nlohmann::json& first = blocks.front();
  if (const auto samples = numeric_samples(blocks)) return as_first(first, post::mean_and_error(*samples).mean);
  if (!first.is_object()) return first;
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [key, value] : first.items()) {
    std::vector<nlohmann::json> values;
    for (const nlohmann::json& b : blocks)
      if (b.contains(key)) values.push_back(b.at(key));
    if (values.size() < blocks.size()) {  // not in every block: the first's
      out[key] = value;
      continue;
    }
    out[key] = mean_with_stderr(values);
    const auto samples = numeric_samples(values);
    if (samples && std::any_of(values.begin(), values.end(), [&](const nlohmann::json& v) { return v != value; }))
      out[key + "_stderr"] = as_first(value, post::mean_and_error(*samples).error);
  }
  return out;
}

std::pair<std::vector<FillSample>, FillBand> mean_curve(const std::vector<std::vector<FillSample>>& curves) {
  std::size_t samples = curves.front().size();
  for (const auto& c : curves) samples = std::min(samples, c.size());
  std::vector<FillSample> mean(samples);
  FillBand band;
  for (std::size_t n = 0; n < samples; ++n) {
    std::vector<std::vector<double>> values;  // per seed: time, shoe, grains, mass
    for (const auto& c : curves) values.push_back({c[n].time, c[n].shoe_x, double(c[n].grains), c[n].mass});
    const post::MeanAndError m = post::mean_and_error(values);
    mean[n].time = m.mean[0], mean[n].shoe_x = m.mean[1], mean[n].grains = std::int64_t(std::llround(m.mean[2]));
    mean[n].mass = m.mean[3];
    band.grains.push_back(m.mean[2]), band.grains_stderr.push_back(m.error[2]), band.mass_stderr.push_back(m.error[3]);
  }
  return {mean, band};
}

namespace {

// The report of the ensemble: the first seed's, its fill, fem and particles the seeds' means
// (with their errors), its stability the worst of them, and what it was made of.
nlohmann::json ensemble_report(const std::vector<DieRun>& runs, const FillProducts& products, const std::vector<std::string>& seeds,
                               double wall_s) {
  nlohmann::json report = runs.front().report;
  report["fill"] = products.fill;
  report["fem"] = products.fem;
  std::vector<nlohmann::json> particles;
  std::string hashes;
  double overlap = 0, energy = 0;
  nlohmann::json warnings = nlohmann::json::array(), folders = nlohmann::json::array();
  nlohmann::json checks = report["stability"]["checks"];
  for (const DieRun& r : runs) {
    particles.push_back(r.report.at("particles"));
    hashes += r.report.at("final_state_sha256").get<std::string>();
    overlap = std::max(overlap, r.report["stability"]["max_overlap_rel"].get<double>());
    energy = std::max(energy, r.report["stability"]["max_energy_gain"].get<double>());
    for (const auto& w : r.report["stability"]["warnings"]) warnings.push_back(w);
    for (auto& [name, passed] : checks.items()) passed = passed.get<bool>() && r.report["stability"]["checks"].value(name, true);
    folders.push_back(fs::relative(r.dir, runs.front().dir.parent_path().parent_path()).string());
  }
  if (!products.fem.is_null()) {  // the hand-off of the mean fill
    checks["fem_no_inverted_element"] = products.fem.at("inverted_elements").get<std::size_t>() == 0;
    checks["fem_mass_within_half_percent"] = std::abs(products.fem.at("mass_error_rel").get<double>()) <= fem_mass_tolerance;
  }
  report["particles"] = mean_with_stderr(particles);
  report["stability"] = {{"max_overlap_rel", overlap}, {"max_energy_gain", energy}, {"checks", checks},
                         {"checks_passed", std::all_of(checks.begin(), checks.end(), [](const auto& c) { return c.template get<bool>(); })},
                         {"warnings", warnings}};
  for (const std::string& w : diefill::log::take_warnings()) report["stability"]["warnings"].push_back(w);  // the ensemble's own
  std::vector<std::uint64_t> numbers;
  for (const std::string& s : seeds) numbers.push_back(std::stoull(s));
  report["run"]["seeds"] = numbers;
  report["timing"]["wall_s"] = wall_s;
  report["final_state_sha256"] = diefill::sha256_hex(hashes);
  report["ensemble"] = {{"seeds", seeds.size()}, {"runs", folders}};
  return report;
}

// The ensemble's outputs into `dir`, from the seeds' runs (rank 0's, which holds their grains).
nlohmann::json write_ensemble(const scene::PipelineScene& first, const std::vector<DieRun>& runs, const std::vector<std::string>& seeds,
                              const diefill::Stopwatch& clock, const fs::path& dir) {
  for (std::size_t k = 0; k < runs.size(); ++k)
    if (runs[k].cavity_grains.empty())
      throw diefill::InputError(runs[k].dir.string(), "particles.in_cavity", fmt::format("seed {} put no grain into the cavity", seeds[k]),
                                "Look at that seed's run: an ensemble of it has no mean field");
  // The seeds' setting, as the sweep ran them (one cache), from the cache the runs filled.
  scene::PipelineScene scene = first;
  if (scene.output.cache.empty()) scene.output.cache = first.output.directory / ".cache";
  const FillSetup setup = set_up_fill(scene, scene.die.file);
  Realisations realisations;
  for (const DieRun& r : runs) realisations.cavity.push_back(r.cavity_grains), realisations.curves.push_back(r.fill_curve);
  diefill::StagingFolder out(dir);
  const FillProducts products = write_fill_products({scene, setup.walls, setup.grains, setup.shoe}, realisations, out.path());
  const nlohmann::json report = ensemble_report(runs, products, seeds, clock.seconds());
  diefill::write_file_atomic(out / "scene.toml", scene::describe(scene));
  diefill::write_file_atomic(out / "report.json", report.dump(2) + "\n");
  out.commit();
  diefill::log::info("{}: {} seeds, fill ratio {:.4f} ± {:.4f} (standard error) -> {}", runs.front().die, seeds.size(),
                     products.fill.value("fill_ratio", 0.0), products.fill.value("fill_ratio_stderr", 0.0), dir.string());
  return report;
}

}  // namespace

DieRun run_ensemble(const std::function<scene::PipelineScene(const std::vector<std::string>& overrides)>& load, int seeds,
                    const std::shared_ptr<dem::Exchange>& ranks) {
  if (seeds < 2)
    throw diefill::InputError("--seeds", "", fmt::format("an ensemble needs two seeds or more, not {}", seeds),
                              "Give --seeds 2 or more, or leave it out for one run");
  diefill::Stopwatch clock;
  const scene::PipelineScene first = load({});
  std::vector<std::string> values;
  for (int k = 0; k < seeds; ++k) values.push_back(std::to_string(first.seed + std::uint64_t(k)));
  const std::vector<DieRun> runs = run_sweep(load, {"simulation.seed", values}, ranks);
  DieRun ensemble;
  ensemble.die = runs.front().die;
  ensemble.dir = first.output.directory / ensemble.die;
  ensemble.interrupted = runs.size() < values.size() || runs.back().interrupted;
  if (ensemble.interrupted) return ensemble;
  // Rank 0 writes; should that fail, every rank learns it before a ladder's next level.
  dem::run_and_agree(ranks.get(), !ranks || ranks->rank() == 0,
                     [&] { ensemble.report = write_ensemble(first, runs, values, clock, ensemble.dir); });
  return ensemble;
}

}  // namespace pipeline
