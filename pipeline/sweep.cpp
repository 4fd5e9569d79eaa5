#include "pipeline/sweep.hpp"

#include <fmt/core.h>

#include <sstream>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "dem/distributed.hpp"
#include "pipeline/pictures.hpp"

namespace pipeline {

namespace fs = std::filesystem;

Sweep parse_sweep(const std::string& text) {
  const auto equals = text.find('=');
  Sweep s;
  if (equals != std::string::npos) {
    s.key = text.substr(0, equals);
    std::stringstream list(text.substr(equals + 1));
    for (std::string value; std::getline(list, value, ',');)
      if (!value.empty()) s.values.push_back(value);
  }
  if (s.key.empty() || s.values.empty())
    throw diefill::InputError("--sweep", "", "'" + text + "' is not KEY=VALUE,VALUE,...",
                              "Give a scene key and its values: --sweep motion.speed=0.05,0.1,0.2");
  return s;
}

std::vector<DieRun> run_sweep(const std::function<scene::PipelineScene(const std::vector<std::string>& overrides)>& load,
                              const Sweep& sweep, const std::shared_ptr<dem::Exchange>& ranks) {
  if (sweep.key.starts_with("output."))
    throw diefill::InputError("--sweep", sweep.key, "says where outputs go, not what is simulated", "Sweep a key that shapes the fill");
  // Every case's scene first: a bad value is refused before any run.
  std::vector<scene::PipelineScene> scenes;
  for (const std::string& value : sweep.values) {
    if (value.find('/') != std::string::npos)
      throw diefill::InputError("--sweep", sweep.key, "value '" + value + "' would name a folder inside another", "Give plain values");
    scenes.push_back(load({sweep.key + "=" + value}));
  }
  const fs::path base = scenes.front().output.directory;
  std::vector<DieRun> runs;
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    scene::PipelineScene& scene = scenes[k];
    if (scene.output.cache.empty()) scene.output.cache = base / ".cache";  // one settled shoe for every case it fits
    scene.output.directory = base / (sweep.key + "=" + sweep.values[k]);
    // Rank 0 writes the outputs after the others have finished the case: should that fail, every
    // rank must learn of it before the next case's collective steps.
    dem::run_and_agree(ranks.get(), true, [&] { runs.push_back(run_die_fill(scene, scene.die.file, false, ranks)); });
    if (runs.back().interrupted) return runs;
  }
  if (ranks && ranks->rank() != 0) return runs;
  std::string csv = fmt::format("{},fill_ratio,mass_kg,grains_in_cavity,spilled,lost,final_state_sha256,folder\n", sweep.key);
  nlohmann::json cases = nlohmann::json::array();
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const nlohmann::json& r = runs[k].report;
    csv += fmt::format("{},{:.9g},{:.9g},{},{},{},{},{}\n", sweep.values[k], r["fill"]["fill_ratio"].get<double>(),
                       r["fill"]["mass_kg"].get<double>(), r["particles"]["in_cavity"].get<std::int64_t>(),
                       r["particles"]["spilled"].get<std::int64_t>(), r["particles"]["lost"].get<std::int64_t>(), r["final_state_sha256"].get<std::string>(), runs[k].dir.string());
    cases.push_back({{"value", sweep.values[k]},
                     {"fill_ratio", r["fill"]["fill_ratio"]},
                     {"mass_kg", r["fill"]["mass_kg"]},
                     {"grains_in_cavity", r["particles"]["in_cavity"]},
                     {"folder", runs[k].dir.string()}});
  }
  // Named by the key, so that a sweep of another key keeps this one's summary.
  const std::string name = "sweep_" + sweep.key;
  diefill::write_file_atomic(base / (name + ".csv"), csv);
  diefill::write_file_atomic(base / (name + ".json"), nlohmann::json({{"key", sweep.key}, {"cases", cases}}).dump(2) + "\n");
  draw_pictures({"sweep", (base / (name + ".json")).string()});
  return runs;
}

}  // namespace pipeline
