// `diefill calibrate`: the design of simulated tests, their maps over the two frictions, and the
// frictions that meet the lab's measurements (calibrate.hpp). The fit and its outputs are in
// calibrate_fit.cpp.
#include "studies/calibrate.hpp"

#include <fmt/core.h>

#include <cmath>
#include <fstream>
#include <map>
#include <numbers>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "core/sha256.hpp"
#include "core/timer.hpp"
#include "dem/model.hpp"
#include "mesh/shapes.hpp"
#include "mesh/sdf.hpp"
#include "pipeline/throughput.hpp"
#include "pipeline/run_loop.hpp"
#include "studies/calibrate_fit.hpp"
#include "studies/study_scenes.hpp"

namespace studies {

namespace fs = std::filesystem;

double beverloo_orifice(double orifice, double d) {
  // The lab's gravity, and the simulated tests' (the scene's default).
  return std::sqrt(9.81) * std::pow(std::max(0.0, orifice - beverloo_k * d), 2.5);
}

SimulatedTests simulated_tests(const scene::PipelineScene& scene, const MeasuredPowder& m, double orifice_grains) {
  scene::PipelineScene s = scene;
  s.powder.particle_diameter = m.particle_diameter;
  s.powder.diameter_spread = m.diameter_spread;
  s.spec.materials[std::size_t(scene::powder_material(s.spec))].density = m.material_density;
  // As coarse as keeps the orifice `orifice_grains` grains wide: Beverloo's k·d then corrects
  // the boundary (docs/PHYSICS.md §4), and every test holds the same few thousand grains
  // whatever the real powder's size.
  s.powder.coarse_graining = std::max(1.0, m.orifice_diameter / (orifice_grains * m.particle_diameter));
  SimulatedTests t{powder_of(s), orifice_grains, m.funnel_half_angle_deg};
  t.powder.source = m.source;
  return t;
}

namespace {

// The flow test: the lowest part of the lab's funnel, its orifice `orifice_grains` wide at
// z = 0 under a cone of the funnel's angle 2.5 times as wide at the top, then a cylinder one
// orifice high; the bed poured on the shut orifice, settled, then drained until the steady rate
// is read (study_scenes.hpp). Hopper flow does not depend on the head above it (Janssen,
// docs/PHYSICS.md §3): the funnel's upper part is left out. Its proportions are the orifice's, not
// the grain's, so that tests at other grain sizes are the same funnel (with the cone six grains
// wider whatever the orifice, an 8-grain orifice's C came out 18 % below a 6-grain one's).
struct Funnel {
  double orifice_radius = 0, top_radius = 0, cone_height = 0, bed_height = 0, pour_height = 0, thickness = 0;
  double inner_radius(double z) const {
    return z >= cone_height ? top_radius : orifice_radius + std::max(0.0, z) / cone_height * (top_radius - orifice_radius);
  }
  // Inside the walls from the orifice's plane up to z [m³].
  double volume_below(double z) const {
    const double h = std::min(z, cone_height), r = inner_radius(h);
    const double cone = std::numbers::pi * h / 3 * (r * r + r * orifice_radius + orifice_radius * orifice_radius);
    return cone + std::numbers::pi * top_radius * top_radius * std::max(0.0, z - cone_height);
  }
};

Funnel test_funnel(const SimulatedTests& t) {
  const double d = t.powder.diameter;
  Funnel f;
  f.orifice_radius = 0.5 * t.orifice_grains * d;
  f.top_radius = 2.5 * f.orifice_radius;
  const double half_angle = t.funnel_half_angle_deg * std::numbers::pi / 180;
  f.cone_height = t.funnel_half_angle_deg >= 89.9 ? 0 : (f.top_radius - f.orifice_radius) / std::tan(half_angle);
  const double cylinder_area = std::numbers::pi * f.top_radius * f.top_radius;
  const double bed_volume = f.volume_below(f.cone_height) + 2 * f.orifice_radius * cylinder_area;
  f.bed_height = f.cone_height + (bed_volume - f.volume_below(f.cone_height)) / cylinder_area;
  // Poured loose at about 0.4 and settling to about 0.6 (study_scenes.cpp's pour height).
  f.pour_height = f.cone_height + (1.5 * bed_volume - f.volume_below(f.cone_height)) / cylinder_area;
  f.thickness = 2 * t.powder.r_max();
  return f;
}

dem::ModelSpec funnel_walls(const Powder& p, const Funnel& f) {
  const double d = p.diameter, top = f.pour_height + 2 * d, outer = f.top_radius + f.thickness;
  const std::vector<std::array<double, 2>> profile = {{f.orifice_radius, -f.thickness}, {outer, -f.thickness}, {outer, top},
                                                      {f.top_radius, top},           {f.top_radius, f.cone_height},
                                                      {f.orifice_radius, 0}};
  const geometry::TriMesh solid = mesh::revolved_solid(profile, mesh::circle_segments(f.orifice_radius, 0.02 * d));
  dem::ModelSpec spec = p.spec;
  spec.meshes = {dem::fixed_mesh_wall(std::make_shared<const geometry::WallField>(mesh::contact_wall_field(solid, p.r_max())), p.wall,
                                      "funnel")};
  const double reach = outer + 2 * d;
  spec.domain = {dem::Vec3(-reach, -reach, -f.thickness - 8 * d), dem::Vec3(reach, reach, top + 2 * d)};
  spec.max_impact_speed = std::max(spec.max_impact_speed, std::sqrt(2 * spec.gravity.norm() * top));
  return spec;
}

// The bed poured into the funnel on its shut orifice and settled, with the solid fraction of
// its core (two grains clear of the walls and of the surface).
SlotBed settle_funnel_bed(const Powder& p, const Funnel& f, const std::string& label) {
  const double d = p.diameter;
  dem::ModelSpec gated = funnel_walls(p, f);
  gated.planes.push_back({dem::Vec3::Zero(), dem::Vec3::UnitZ(), p.wall, "gate"});
  SlotBed bed;
  dem::InsertRegion region;
  region.box = {dem::Vec3(-f.top_radius, -f.top_radius, 0), dem::Vec3(f.top_radius, f.top_radius, f.pour_height)};
  region.accept = [&](const dem::Vec3& x, double radius) {
    return x.z() > radius && std::hypot(x.x(), x.y()) + 1.5 * radius <= f.inner_radius(x.z() - radius);
  };
  add_grains(bed.state, region, p, std::size_t(0.6 * f.volume_below(f.bed_height) / grain_volume(d)), p.seed);
  const dem::Model shut = dem::compile_model(gated, bed.state, p.source);
  dem::initialize(shut, bed.state);
  advance(shut, bed.state, 0.2, label + ": settling");
  bed.bed_height = centre_height_quantile(bed.state, 0.97);
  double solid = 0, core_volume = 0;
  const double lo = 2 * d, hi = bed.bed_height - 2 * d, slice = 0.05 * d;
  for (double s = lo; s < hi; s += slice) core_volume += std::numbers::pi * std::pow(std::max(0.0, f.inner_radius(s) - 2 * d), 2) * slice;
  for (std::size_t i = 0; i < bed.state.size(); ++i) {
    const dem::Vec3& x = bed.state.x[i];
    if (x.z() > lo && x.z() < hi && std::hypot(x.x(), x.y()) < f.inner_radius(x.z()) - 2 * d) solid += grain_volume(2 * bed.state.radius[i]);
  }
  if (core_volume <= 0) throw diefill::InputError(p.source, "funnel", "leaves no bed to measure", "Report this: the funnel is too small");
  bed.bulk_density = p.density * solid / core_volume;
  bed.initial_mass = mass_where(bed.state, [&](std::size_t i) { return bed.state.active[i] != 0; });
  return bed;
}

// The heap settles for 40 grain times √(d/g) after the pour: with the repose study's 0.15 s,
// heaps of 2.4 mm spheres (9.6 grain times) stood at 24.7° ± 0.5° and of 1.8 mm (11.3) at 27.6° ±
// 0.3° for one powder (three seeds each); after 0.5 s, 27.2° ± 0.7° and 27.0° ± 0.8°.
Heap test_heap(const SimulatedTests& t) {
  Heap heap = funnel_heap(t.powder.diameter, 10);
  heap.settle_time = 40 * std::sqrt(t.powder.diameter / t.powder.spec.gravity.norm());
  return heap;
}

}  // namespace

TestResults run_tests(const SimulatedTests& t, double sliding, double rolling, std::uint64_t seed, const std::string& label) {
  Powder p = t.powder;
  dem::Material& grain = p.spec.materials[std::size_t(p.powder)];
  grain.sliding_friction = sliding;
  grain.rolling_friction = rolling;
  p.seed = seed;
  const double d = p.diameter;
  TestResults r;
  const Heap heap = test_heap(t);
  r.repose_deg = fit_heap_surface(run_heap(p, heap, label + ", heap").state, heap, d).angle_deg;

  const Funnel funnel = test_funnel(t);
  SlotContainer timing;
  timing.flow_time = 1.5;
  timing.stop_after_steady_flow = true;
  const SlotRun run = drain_bed(p, funnel_walls(p, funnel), timing, settle_funnel_bed(p, funnel, label + ", funnel"),
                                -funnel.thickness - d, label + ", funnel");
  r.beverloo_c = steady_rate(run).slope / (run.bulk_density * beverloo_orifice(2 * funnel.orifice_radius, d));
  r.solid_fraction = run.bulk_density / p.density;
  diefill::log::info("{}: repose {:.1f}°, Beverloo C {:.3f}, solid fraction {:.3f}", label, r.repose_deg, r.beverloo_c,
                     r.solid_fraction);
  return r;
}

namespace {

// The design: μ 0.2, 0.5 and 0.8 by μ_r 0, 0.15 and 0.3, where powders' calibrated spheres lie
// (docs/PHYSICS.md §3), each on `repeats` seeds; the centre on one seed more, so that even one seed
// a point leaves the maps' scatter four degrees of freedom. Three levels of each, because the
// results bend over the design: the centre's heap stood 2.2° above the corners' mean, its poured
// solid fraction 0.018 below (docs/STUDIES.md, "calibration-round-trip"), which a map through the
// corners alone took for noise and the fit for frictions 0.11 off.
std::vector<DesignPoint> design(std::uint64_t seed, int repeats) {
  std::vector<DesignPoint> points;
  for (const double sliding : {0.2, 0.5, 0.8})
    for (const double rolling : {0.0, 0.15, 0.3}) {
      const int extra_seeds = sliding == 0.5 && rolling == 0.15 ? 1 : 0;
      for (int k = 0; k < repeats + extra_seeds; ++k) points.push_back({sliding, rolling, seed + std::uint64_t(k)});
    }
  return points;
}

// What makes a test's result: the measured file's values that shape the tests, the scene's keys,
// the design point and the DEM's code.
std::string test_key(const MeasuredPowder& m, const CalibrateRequest& c, const DesignPoint& p) {
  std::string keys;
  for (const std::string& o : c.overrides) keys += o + ";";
  return diefill::sha256_hex(fmt::format("{} {} {} {} {} {} {} {} {}", m.particle_diameter, m.diameter_spread, m.material_density,
                                         m.orifice_diameter, m.funnel_half_angle_deg, keys, p.sliding, p.rolling, p.seed) +
                             std::string(dem::source_hash()));
}

// The finished tests of an interrupted calibration: one JSON line each, kept in OUT.
fs::path checkpoint_of(const fs::path& out) { return out / ".calibration_tests.jsonl"; }

std::map<std::string, TestResults> finished_tests(const fs::path& file) {
  std::map<std::string, TestResults> done;
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) {
    const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_discarded() || !j.contains("key")) continue;  // a line cut by the interruption
    done[j["key"]] = {j["repose_deg"], j["beverloo_c"], j["solid_fraction"]};
  }
  return done;
}

void record_test(const fs::path& file, const std::string& key, const TestResults& r) {
  std::ofstream out(file, std::ios::app);
  out << nlohmann::json{{"key", key}, {"repose_deg", r.repose_deg}, {"beverloo_c", r.beverloo_c}, {"solid_fraction", r.solid_fraction}}
             .dump()
      << "\n";
  if (!out) throw diefill::InputError(file.string(), "", "cannot be written", "Free space or choose another -o folder");
}

// The wall time the design will take on this machine, before any test runs: the tests'
// particle-steps over the kernel's measured rate at a fill's efficiency (pipeline/throughput.hpp).
double estimated_seconds(const scene::PipelineScene& scene, const SimulatedTests& t, std::size_t tests, const fs::path& cache) {
  const Powder& p = t.powder;
  dem::State one;
  dem::InsertRegion region;
  region.box = {dem::Vec3::Zero(), dem::Vec3::Constant(4 * p.diameter)};
  add_grains(one, region, p, 1, 1);
  const double dt = dem::compile_model(p.spec, one, p.source).dt;
  const Heap heap = test_heap(t);
  const Funnel f = test_funnel(t);
  const double bed_grains = 0.6 * f.volume_below(f.bed_height) / grain_volume(p.diameter);
  // The heap pours for a second (half its grains on average) and settles; the funnel's bed
  // settles and drains 40 % at Beverloo's rate with C = 0.58.
  const double rate = 0.58 * 0.6 * p.density * beverloo_orifice(2 * f.orifice_radius, p.diameter);
  const double drain = 0.2 + 0.4 * bed_grains * grain_volume(p.diameter) * p.density / rate;
  const double particle_steps = (double(heap.grains) * (0.5 + heap.settle_time) + bed_grains * drain) / dt;
  const pipeline::GrainSizing grains{p.diameter, p.r_max(), 1, 0};
  const double kernel = pipeline::kernel_rate(scene, grains, cache);
  return double(tests) * pipeline::TimeModel{}.predict(particle_steps, kernel);
}

}  // namespace

int run_calibrate(const CalibrateRequest& c) {
  const MeasuredPowder measured = read_measured_powder(c.measured);
  scene::PipelineScene scene = scene::load_pipeline_scene(std::nullopt, c.overrides);
  if (c.threads) scene.threads = *c.threads;
  const pipeline::ThreadCount threads(scene.threads);
  const SimulatedTests tests = simulated_tests(scene, measured, 6);
  fs::create_directories(c.out);
  const fs::path checkpoint = checkpoint_of(c.out);
  if (!c.resume) fs::remove(checkpoint);
  std::map<std::string, TestResults> done = finished_tests(checkpoint);

  const std::vector<DesignPoint> points = design(c.seed, c.repeats);
  std::size_t to_run = 0;
  for (const DesignPoint& p : points) to_run += !done.contains(test_key(measured, c, p));
  diefill::log::info("calibrate: spheres of {:.3g} mm stand for {:.3g} mm grains (the orifice {:.0f} of them wide); {} of {} tests to "
                     "run, about {:.1f} min",
                     tests.powder.diameter * 1e3, measured.particle_diameter * 1e3, tests.orifice_grains, to_run,
                     points.size(), estimated_seconds(scene, tests, to_run, c.out / ".cache") / 60);
  diefill::Stopwatch clock;
  std::vector<Finished> results;
  try {
    for (std::size_t k = 0; k < points.size(); ++k) {
      const DesignPoint& p = points[k];
      const std::string key = test_key(measured, c, p);
      if (!done.contains(key)) {
        done[key] = run_tests(tests, p.sliding, p.rolling, p.seed,
                              fmt::format("calibrate: test {} of {} (μ = {:.2f}, μ_r = {:.2f}, seed {})", k + 1, points.size(),
                                          p.sliding, p.rolling, p.seed));
        record_test(checkpoint, key, done[key]);
      }
      results.push_back({p, done[key]});
    }
  } catch (const Interrupted&) {
    fmt::print(stderr, "interrupted; the finished tests are kept: `diefill calibrate {} -o {} --resume` goes on\n",
               c.measured.string(), c.out.string());
    return diefill::exit_interrupted;
  }
  const CalibrationFit fit = fit_frictions(results, measured, tests);
  write_calibration(c.out, measured, tests, results, fit);
  diefill::log::info("calibrate: {:.0f} s -> {}", clock.seconds(), (c.out / "calibrated.toml").string());
  return 0;
}

}  // namespace studies
