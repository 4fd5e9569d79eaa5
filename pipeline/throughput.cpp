#include "pipeline/throughput.hpp"

#include <fmt/core.h>
#include <omp.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "core/atomic_file.hpp"
#include "core/timer.hpp"
#include "dem/insert.hpp"
#include "dem/model.hpp"
#include "dem/step.hpp"
#include "pipeline/run_loop.hpp"

namespace pipeline {

namespace fs = std::filesystem;

namespace {

std::string processor_name() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.starts_with("model name")) return line.substr(line.find(':') + 2);
  return "unknown processor";
}

int threads_of(const scene::PipelineScene& s) { return s.threads > 0 ? s.threads : omp_get_max_threads(); }

nlohmann::json read_json(const fs::path& file) {
  std::ifstream in(file);
  if (!in) return nlohmann::json::object();
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception&) {
    return nlohmann::json::object();  // a broken cache is measured afresh
  }
}

// 4,000 of the scene's grains in a box of planes 20 grains wide, inserted as densely as random
// insertion goes (a bed of grains in contact, as a fill's mostly is): 100 steps to start, then
// the particle-steps per second of the fastest of five blocks of 60 (another process that takes a
// core for a moment slows a block, not the figure).
double measure_kernel(const scene::PipelineScene& s, const GrainSizing& grains) {
  dem::ModelSpec spec = scene::coarse_grained_spec(s.spec, grains.alpha);
  const int powder = scene::powder_material(spec), steel = scene::tool_material(spec);
  const double d = grains.diameter, half = 10 * d;
  spec.planes = {{dem::Vec3::Zero(), dem::Vec3::UnitZ(), steel, "floor"},
                 {dem::Vec3(-half, 0, 0), dem::Vec3::UnitX(), steel, "x-"}, {dem::Vec3(half, 0, 0), -dem::Vec3::UnitX(), steel, "x+"},
                 {dem::Vec3(0, -half, 0), dem::Vec3::UnitY(), steel, "y-"}, {dem::Vec3(0, half, 0), -dem::Vec3::UnitY(), steel, "y+"}};
  spec.domain = {dem::Vec3(-half, -half, -d), dem::Vec3(half, half, 60 * d)};
  dem::State state;
  dem::InsertRegion region;
  region.box = {dem::Vec3(-half + 0.5 * d, -half + 0.5 * d, 0.5 * d), dem::Vec3(half - 0.5 * d, half - 0.5 * d, 12 * d)};
  dem::InsertRequest request;
  request.count = 4000;
  request.max_solid_fraction = 0.45;
  request.radius = 0.5 * d;
  request.radius_spread = s.powder.diameter_spread;
  request.material = powder;
  request.density = spec.materials[std::size_t(powder)].density;
  dem::insert_spheres(state, region, request);
  const dem::Model model = dem::compile_model(spec, state, "throughput kernel");
  dem::initialize(model, state);
  for (int n = 0; n < 100; ++n) dem::step(model, state);
  double fastest = 0;
  for (int block = 0; block < 5; ++block) {
    const diefill::Stopwatch clock;
    for (int n = 0; n < 60; ++n) dem::step(model, state);
    fastest = std::max(fastest, 60.0 * double(state.size()) / clock.seconds());
  }
  return fastest;
}

}  // namespace

std::string machine_key(int threads) {
  return fmt::format("{}; {} hardware threads; {} threads; dem {}", processor_name(), std::thread::hardware_concurrency(), threads,
                     dem::source_hash());
}

double kernel_rate(const scene::PipelineScene& s, const GrainSizing& grains, const fs::path& cache) {
  const fs::path file = cache / "throughput.json";
  nlohmann::json rates = read_json(file);
  const std::string key = machine_key(threads_of(s));
  const double measured = [&] {
    const ThreadCount threads(threads_of(s));
    return measure_kernel(s, grains);
  }();
  // The fastest this machine has shown is kept: measured once and kept, a rate taken beside
  // another busy process (2 to 35 times below the idle machine's beside a test) lengthened every
  // later plan on the machine.
  if (const double kept = rates.value(key, 0.0); kept >= measured) return kept;
  rates[key] = measured;
  fs::create_directories(cache);
  diefill::write_file_atomic(file, rates.dump(2) + "\n");
  return measured;
}

TimeModel time_model(const fs::path& cache, double rate) {
  // Least squares of wall = a + b·(particle-steps / rate) over this machine's runs.
  std::ifstream in(cache / "timings.jsonl");
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::string line; std::getline(in, line);) {
    try {
      const nlohmann::json j = nlohmann::json::parse(line);
      if (j.value("machine", "") != machine_key(j.value("threads", 0))) continue;
      const double x = j["particle_steps"].get<double>() / j.value("kernel_rate", rate), y = j["wall_s"].get<double>();
      n += 1, sx += x, sy += y, sxx += x * x, sxy += x * y;
    } catch (const nlohmann::json::exception&) {
      continue;  // a line another writer cut short
    }
  }
  TimeModel model;
  const double delta = n * sxx - sx * sx;
  if (n >= 3 && delta > 0) {
    const double b = (n * sxy - sx * sy) / delta, a = (sy - b * sx) / n;
    if (b > 0 && a >= 0) model = {a, 1 / b, int(n)};
  }
  return model;
}

void record_timing(const fs::path& cache, double particle_steps, double wall_s, int threads) {
  const nlohmann::json rates = read_json(cache / "throughput.json");
  const std::string key = machine_key(threads);
  nlohmann::json line = {{"machine", key}, {"threads", threads}, {"particle_steps", particle_steps}, {"wall_s", wall_s}};
  if (rates.contains(key)) line["kernel_rate"] = rates[key];
  fs::create_directories(cache);
  std::ofstream out(cache / "timings.jsonl", std::ios::app);
  out << line.dump() << "\n";
}

}  // namespace pipeline
