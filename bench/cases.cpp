// `diefill bench`'s cases (cases.hpp). The particle cases are timed on each thread count asked,
// after a warm-up.
#include "bench/cases.hpp"

#include <fmt/core.h>
#include <omp.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "bench/mpi_bed.hpp"
#include "dem/checkpoint.hpp"
#include "dem/distributed.hpp"
#include "pipeline/die_fill.hpp"
#include "core/error.hpp"
#include "core/resources.hpp"
#include "core/sha256.hpp"
#include "core/log.hpp"
#include "core/timer.hpp"
#include "dem/insert.hpp"
#include "dem/io.hpp"
#include "dem/neighbours.hpp"
#include "dem/step.hpp"
#include "mesh/die.hpp"

namespace bench {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The LIGGGHTS reference material: d = 1 mm, 2500 kg/m³, E = 5 MPa, ν = 0.3, e = 0.5, μ = 0.5,
// constant directional torque rolling resistance 0.1 (in/common.in).
dem::Material reference_material() {
  dem::Material m;
  m.name = "reference";
  m.density = 2500;
  m.youngs_modulus = 5e6;
  m.poisson_ratio = 0.3;
  m.restitution = 0.5;
  m.sliding_friction = 0.5;
  m.rolling_friction = 0.1;
  return m;
}

dem::ModelSpec reference_spec() {
  dem::ModelSpec spec;
  spec.materials = {reference_material()};
  spec.law.normal = "hertz";
  spec.law.tangential = "mindlin";
  spec.law.rolling = "cdt";
  spec.time_step = 1e-6;       // as bench.in
  spec.skin = 0.25e-3;         // "neighbor 0.00025 bin"
  spec.max_impact_speed = 0.5;
  return spec;
}

// LAMMPS "dump custom" with columns id x y z radius vx vy vz.
dem::State read_lammps_dump(const fs::path& path, const dem::Material& m) {
  std::ifstream in(path);
  if (!in) throw diefill::InputError(path.string(), "", "cannot be read", "Run the LIGGGHTS preparation first (bench/compare_liggghts.sh)");
  std::string line;
  std::vector<std::string> columns;
  while (std::getline(in, line))
    if (line.rfind("ITEM: ATOMS", 0) == 0) {
      std::istringstream names(line.substr(11));
      for (std::string c; names >> c;) columns.push_back(c);
      break;
    }
  auto col = [&](const std::string& name) {
    for (std::size_t c = 0; c < columns.size(); ++c)
      if (columns[c] == name) return c;
    throw diefill::InputError(path.string(), "column " + name, "is missing", "Dump id x y z radius vx vy vz");
  };
  const std::size_t id = col("id"), x = col("x"), y = col("y"), z = col("z"), r = col("radius");
  dem::State s;
  while (std::getline(in, line)) {
    std::istringstream row(line);
    std::vector<double> v;
    for (double d; row >> d;) v.push_back(d);
    if (v.size() < columns.size()) continue;
    s.add_sphere(std::int64_t(v[id]), dem::Vec3(v[x], v[y], v[z]), v[r], m.density, 0);
  }
  return s;
}


// A line of /proc/self/status in bytes ("VmRSS:", the resident set now; "VmHWM:", its peak
// since the last reset_resident_peak()); 0 where the file is not there.
double status_bytes(const std::string& field) {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind(field, 0) == 0) return 1024.0 * std::stod(line.substr(field.size()));  // kB
  return 0;
}
void reset_resident_peak() { std::ofstream("/proc/self/clear_refs") << "5"; }

json time_case(const std::string& name, const dem::Model& model, const dem::State& pack, int steps,
               const std::vector<int>& thread_counts, const std::shared_ptr<dem::Exchange>& exchange) {
  const int ranks = exchange ? exchange->ranks() : 1;
  // Over the ranks (the local value on one process).
  const auto total = [&](double local) { return exchange ? exchange->sum(local) : local; };
  const auto largest = [&](double local) { return exchange ? exchange->max(local) : local; };
  const double grains = double(pack.size());
  json runs = json::array();
  for (int threads : thread_counts) {
    omp_set_num_threads(threads);
    // What the run holds at its peak, from its state on: the arrays with the allocator's rounding,
    // the rebuilds' scratch and the threads' buffers (bytes_per_particle below counts the arrays).
    reset_resident_peak();
    const double resident_before = status_bytes("VmRSS:");
    dem::State s = dem::share_of(pack, exchange);
    dem::initialize(model, s);
    // A step that fails its checks ends the benchmark: a rate measured on a failed state (grains
    // driven into each other, every step then scanning for the worst overlap) is not a speed.
    const auto checked = [&](const dem::StepReport& report) {
      if (report.status != dem::StepStatus::ok) throw diefill::StabilityError(fmt::format("bench {}: {}", name, report.message), model.dt);
    };
    for (int n = 0; n < std::min(200, steps / 10); ++n) checked(dem::step(model, s));  // warm-up
    // A bed that gains or loses contacts while it is timed is not the bed of its size (settled_bed).
    const double contacts_at_start = total(double(s.counters.contacts)) * 2.0 / grains;
    dem::StageTimes times;
    largest(0);  // every rank starts the clock together
    diefill::Stopwatch clock;
    const std::int64_t builds = s.neighbours.builds;
    for (int n = 0; n < steps; ++n) checked(dem::step(model, s, &times));
    const double wall = largest(clock.seconds());
    const double rate = double(steps) * grains / wall;
    runs.push_back({{"threads", threads},
                    {"ranks", ranks},
                    {"steps", steps},
                    {"wall_s", wall},
                    {"particle_steps_per_s", rate},
                    {"particle_steps_per_s_per_core", rate / (threads * ranks)},
                    {"neighbour_builds", s.neighbours.builds - builds},
                    {"contacts_per_grain_at_start", contacts_at_start},
                    {"contacts_per_grain", total(double(s.counters.contacts)) * 2.0 / grains},
                    {"listed_pairs_per_grain", total(double(s.neighbours.partner.size())) * 2.0 / grains},
                    {"near_wall_grains", total(double(s.neighbours.near_wall.size()))},
                    {"wall_contacts", total(double(s.counters.wall_contacts))},
                    {"stages_s",
                     {{"neighbours", times.neighbours},
                      {"pair_forces", times.pair_forces},
                      {"sums", times.sums},
                      {"wall_forces", times.wall_forces},
                      {"integration", times.integration},
                      {"monitor", times.monitor}}}});
    // One neighbour rebuild timed on its own (a settled bed seldom needs one), as a fraction of a
    // step: a flowing powder rebuilds every skin / (2 v dt) steps or so, and pays that much.
    if (!exchange) {
      diefill::Stopwatch rebuild_clock;
      dem::rebuild_neighbours(model, s);
      const double rebuild = rebuild_clock.seconds();
      runs.back()["rebuild_s"] = rebuild;
      runs.back()["rebuild_over_step"] = rebuild / (wall / steps);
      runs.back()["peak_resident_bytes_per_particle"] = (status_bytes("VmHWM:") - resident_before) / grains;
    }
    diefill::log::info("bench {}: {} threads, {:.3g} particle-steps/s", name, threads, rate);
    if (threads == thread_counts.back()) {
      // Per owned grain, ghosts included, on the rank that holds the most.
      runs.back()["bytes_per_particle"] = largest(double(s.memory_bytes()) / double(std::max<std::size_t>(1, s.owned())));
      if (exchange) {
        runs.back()["largest_share_of_grains_with_ghosts"] = largest(double(s.size()) / grains);
        runs.back()["ghost_bytes_per_step"] = largest(double(exchange->ghost_bytes_per_step()));
      }
    }
  }
  return {{"case", name}, {"grains", pack.size()}, {"dt_s", model.dt}, {"runs", runs}};
}

// A settled dense pack of `count` equal spheres in the ring die, cached under `cache`.
std::pair<dem::Model, dem::State> ring_pack(std::size_t count, const fs::path& cache) {
  // Grain size such that the count fills the cavity about 1.5 times at a solid fraction 0.6.
  const double cavity = 3.14159265358979 * (100e-6 - 25e-6) * 10e-3;
  const double r = std::cbrt(0.6 * 1.5 * cavity / double(count) / (4.0 / 3.0 * 3.14159265358979)) / 1.0;
  mesh::DieOptions options = mesh::die_options_for_grains(r, 0.5 * r);
  options.table_margin_m = 4e-3;
  const mesh::PreparedDie die = mesh::prepare_die(diefill::resource_path("dies/ring.stl"), options, cache);
  dem::ModelSpec spec = reference_spec();
  spec.time_step.reset();
  spec.skin = 0.5 * r;
  spec.gravity = dem::Vec3(0, 0, -9.81);
  spec.domain = {dem::Vec3(-14e-3, -14e-3, -11e-3), dem::Vec3(14e-3, 14e-3, 30e-3)};
  spec.meshes.push_back(dem::fixed_mesh_wall(std::make_shared<const geometry::WallField>(die.sdf.wall_field(die.solid)), 0, "ring"));
  const fs::path packed = cache / fmt::format("ring_pack_{}.csv", count);
  dem::State s;
  if (fs::exists(packed)) {
    s = dem::read_particles_csv(packed, 0, 2500);
  } else {
    diefill::log::info("bench: preparing a settled pack of {} grains in the ring (once; cached in {})", count, packed.string());
    dem::InsertRegion region;
    region.box = {dem::Vec3(-9.9e-3, -9.9e-3, -9.9e-3), dem::Vec3(9.9e-3, 9.9e-3, 28e-3)};
    region.accept = [](const dem::Vec3& p, double radius) {
      const double rho = p.head<2>().norm();
      return rho < 10e-3 - radius && rho > 5e-3 + radius;
    };
    dem::InsertRequest req;
    req.count = count;
    req.radius = r;
    req.max_solid_fraction = 0.5;
    dem::insert_spheres(s, region, req);
    const dem::Model settle = dem::compile_model(spec, s, "bench");
    dem::initialize(settle, s);
    double fastest = 1;
    while (fastest > 0.01 && s.time < 0.5) {
      for (int n = 0; n < 2000; ++n) dem::step(settle, s);
      fastest = 0;
      for (const dem::Vec3& v : s.v) fastest = std::max(fastest, v.norm());
    }
    for (dem::Vec3& v : s.v) v.setZero();
    for (dem::Vec3& w : s.w) w.setZero();
    dem::write_particles_csv(s, packed);
  }
  // The cached pack keeps the grains its settling lost (they left the domain, over the table's
  // edge): they are no grains of the bench, and one may overlap another where it fell.
  dem::State fresh;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (spec.domain.contains(s.x[i])) fresh.add_sphere(s.id[i], s.x[i], s.radius[i], 2500, 0);
  return {dem::compile_model(spec, fresh, "bench"), fresh};
}

// The scaling case: dense beds of `count` grains cut from the settled LIGGGHTS pack (the grains
// wholly inside a square column of it, so that none overlaps the column's walls; one column per
// tile, tiles side by side a grain apart in a box of planes), so that every size is the same
// powder, and no hour-long pour is needed for half a million grains. Tiles hold the column's grains
// lowest first. A bed smaller than one tile is a narrower square of the column. Cut out so, a bed
// is not at rest (settled_bed).
std::pair<dem::Model, dem::State> tiled_pack(const dem::State& source, std::size_t count) {
  constexpr double column = 30e-3;  // the largest square the 44 mm cylinder holds, nearly
  std::vector<std::size_t> in_column;
  for (std::size_t i = 0; i < source.size(); ++i)
    if (std::max(std::abs(source.x[i].x()), std::abs(source.x[i].y())) + source.radius[i] < 0.5 * column) in_column.push_back(i);
  std::sort(in_column.begin(), in_column.end(), [&](std::size_t a, std::size_t b) { return source.x[a].z() < source.x[b].z(); });
  const std::size_t per_tile = in_column.size();
  const std::size_t tiles = (count + per_tile - 1) / per_tile;
  const int side = int(std::ceil(std::sqrt(double(tiles))));
  const double pitch = column + 1e-3, z0 = source.x[in_column.front()].z() - source.radius[in_column.front()];
  // A single tile smaller than the column: the square of the same height that holds `count`.
  const double shrink = tiles == 1 ? std::sqrt(double(count) / double(per_tile)) : 1.0;
  dem::State s;
  for (std::size_t t = 0; t < tiles && s.size() < count; ++t) {
    const dem::Vec3 shift(double(int(t) % side) * pitch, double(int(t) / side) * pitch, -z0);
    for (std::size_t i : in_column) {
      if (s.size() == count) break;
      if (shrink < 1 && std::max(std::abs(source.x[i].x()), std::abs(source.x[i].y())) + source.radius[i] > 0.5 * column * shrink) continue;
      s.add_sphere(std::int64_t(s.size()), source.x[i] + shift, source.radius[i], 2500, 0);
    }
  }
  dem::ModelSpec spec = reference_spec();
  spec.gravity = dem::Vec3(0, 0, -9.81);
  const double lo = -0.5 * column * shrink, hi_x = lo + double(std::min<int>(side, int(tiles)) - 1) * pitch + column * shrink;
  const double hi_y = lo + double((int(tiles) + side - 1) / side - 1) * pitch + column * shrink;
  spec.planes = {{dem::Vec3(0, 0, 0), dem::Vec3::UnitZ(), 0, "floor"},
                 {dem::Vec3(lo, 0, 0), dem::Vec3::UnitX(), 0, "side"},
                 {dem::Vec3(hi_x, 0, 0), -dem::Vec3::UnitX(), 0, "side"},
                 {dem::Vec3(0, lo, 0), dem::Vec3::UnitY(), 0, "side"},
                 {dem::Vec3(0, hi_y, 0), -dem::Vec3::UnitY(), 0, "side"}};
  spec.domain = {dem::Vec3(lo, lo, 0) - dem::Vec3::Constant(2e-3), dem::Vec3(hi_x, hi_y, 0.1) + dem::Vec3::Constant(2e-3)};
  return {dem::compile_model(spec, s, "bench scaling"), s};
}

// A tiled bed has lost the grains that pressed on it (above, or beside it in the cylinder): it
// springs apart and falls back for tens of milliseconds, and timed so, its contacts fall (4.4 to
// 0.45-2.75 per grain in 2,000 steps) and fewer contacts make a faster step, so the sizes would
// not be like for like (docs/PERFORMANCE.md, "Against the grain count"). The bed is stepped until
// it rests by the LIGGGHTS preparation's own criterion (mean kinetic energy per grain below
// 1e-12 J, ../shared/bench/liggghts/in/prep.in) and kept at `path` as a checkpoint, contact
// histories included, so that the timed steps go on from a bed at rest. Made once per size, pack
// and model (the path's hash); under MPI by rank 0 alone.
dem::State settled_bed(const dem::Model& model, dem::State bed, const fs::path& path, const std::shared_ptr<dem::Exchange>& ranks) {
  if (!fs::exists(path) && (!ranks || ranks->rank() == 0)) {
    constexpr double at_rest_J = 1e-12, longest_s = 0.5;
    constexpr int steps_between_checks = 2000;
    const double grains = double(bed.size());
    diefill::log::info("bench: settling the tiled bed of {} grains (once; kept in {})", bed.size(), path.string());
    dem::initialize(model, bed);
    for (double per_grain = dem::kinetic_energy(bed) / grains;;) {
      for (int n = 0; n < steps_between_checks; ++n)
        if (const dem::StepReport report = dem::step(model, bed); report.status != dem::StepStatus::ok)
          throw diefill::StabilityError(fmt::format("bench scaling: settling {} grains: {}", bed.size(), report.message), model.dt);
      per_grain = dem::kinetic_energy(bed) / grains;
      diefill::log::info("bench: {} grains at t = {:.3f} s: {:.2e} J per grain (at rest below {:.0e})", bed.size(), bed.time, per_grain, at_rest_J);
      if (per_grain < at_rest_J) break;
      if (bed.time > longest_s)
        throw std::runtime_error(fmt::format("bench scaling: the bed of {} grains is not at rest after {} s ({:.2e} J per grain): "
                                             "a rate measured on it would not be like for like",
                                             bed.size(), longest_s, per_grain));
    }
    fs::create_directories(path.parent_path());
    dem::write_checkpoint(model, bed, path);
  }
  if (ranks) ranks->barrier();
  return dem::read_checkpoint(model, path);
}

}  // namespace

json run_cases(const Request& c, const std::shared_ptr<dem::Exchange>& ranks) {
  std::vector<std::string> cases = c.cases;
  if (cases.empty()) cases = {"ring-10k", "ring-100k"};
  std::vector<int> thread_counts = c.threads;
  if (thread_counts.empty()) thread_counts = {1, 2};
  json results = {{"machine", {{"hardware_threads", std::thread::hardware_concurrency()}}}, {"cases", json::array()}};
  for (const std::string& name : cases) {
    if (name == "ring-10k" || name == "ring-100k") {
      auto [model, pack] = ring_pack(name == "ring-10k" ? 10000 : 100000, c.cache);
      results["cases"].push_back(time_case(name, model, pack, c.steps, thread_counts, ranks));
    } else if (name == "liggghts") {
      if (c.pack.empty() || c.stl.empty())
        throw diefill::InputError("bench liggghts", "--pack/--stl", "the LIGGGHTS case needs the settled pack and the container",
                                  "Run bench/compare_liggghts.sh, which prepares both");
      dem::ModelSpec spec = reference_spec();
      spec.gravity = dem::Vec3(0, 0, -9.81);
      dem::State pack = read_lammps_dump(c.pack, spec.materials[0]);
      mesh::DieOptions options = mesh::die_options_for_grains(0.5e-3, 0.25e-3);
      options.role = mesh::WallRole::container;
      const mesh::PreparedDie die = mesh::prepare_die(c.stl, options, c.cache);
      const geometry::Box box = die.after.bbox;
      spec.domain = {dem::Vec3(box.lo.x(), box.lo.y(), box.lo.z()) - dem::Vec3::Constant(1e-3),
                     dem::Vec3(box.hi.x(), box.hi.y(), box.hi.z()) + dem::Vec3::Constant(1e-3)};
      spec.meshes.push_back(dem::fixed_mesh_wall(std::make_shared<const geometry::WallField>(die.sdf.wall_field(die.solid)), 0, "container"));
      const dem::Model model = dem::compile_model(spec, pack, c.pack.string());
      json r = time_case(name, model, pack, c.steps, thread_counts, ranks);
      r["pack"] = c.pack.string();
      r["container"] = c.stl.string();
      r["container_triangles"] = die.after.triangles;
      results["cases"].push_back(r);
    } else if (name == "scaling") {
      if (c.pack.empty())
        throw diefill::InputError("bench scaling", "--pack", "the scaling case tiles the settled LIGGGHTS pack",
                                  "Run bench/scaling.sh, which prepares it");
      const dem::State source = read_lammps_dump(c.pack, reference_material());
      const std::string pack_hash = diefill::sha256_file(c.pack);
      for (std::size_t count : c.sizes) {
        auto [model, tiled] = tiled_pack(source, count);
        const std::string key = diefill::sha256_hex(pack_hash + model.hash).substr(0, 16);
        const dem::State bed = settled_bed(model, std::move(tiled), c.cache / fmt::format("scaling_bed_{}_{}.ckpt", count, key), ranks);
        results["cases"].push_back(time_case(fmt::format("scaling-{}", count), model, bed, c.steps, thread_counts, ranks));
      }
    } else if (name == "run-ring") {
      scene::PipelineScene scene = scene::load_pipeline_scene(std::nullopt, {});
      scene.output.directory = c.cache / "run-ring";
      if (!ranks || ranks->rank() == 0) fs::remove_all(scene.output.directory);
      if (ranks) ranks->barrier();
      diefill::Stopwatch clock;
      const pipeline::DieRun run = pipeline::run_die_fill(scene, diefill::resource_path("dies/ring.stl"), false, ranks);
      results["cases"].push_back({{"name", name},
                                  {"threads", omp_get_max_threads()},
                                  {"wall_s", clock.seconds()},
                                  {"grains", run.report["particles"]["inserted"]},
                                  {"fill_ratio", run.report["fill"]["fill_ratio"]},
                                  {"timing", run.report["timing"]}});
    } else if (name == "mpi-bed") {
      results["cases"].push_back(run_mpi_bed(c, ranks));
    } else {
      throw diefill::InputError("bench", name, "is not a benchmark case", "Use ring-10k, ring-100k, liggghts, scaling, run-ring or mpi-bed");
    }
  }
  return results;
}

}  // namespace bench
