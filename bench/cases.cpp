// `diefill bench`'s cases (cases.hpp). The particle cases are timed on each thread count asked,
// after a warm-up.
#include "bench/cases.hpp"

#include <fmt/core.h>
#include <omp.h>

#include <fstream>
#include <numeric>
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

// The scaling case: beds of 5k to 500k grains made of tiles cut from the settled LIGGGHTS pack,
// so that every size is the same powder and no hour-long pour is needed for half a million grains.
// A tile is the lowest grains wholly inside a square column of the pack (none overlaps the tile's
// walls); a bed of several tiles holds equal tiles side by side, filling a rectangle in one box of
// planes; a bed smaller than the column is a narrower square of the column's height. Cut out so, a
// tile has lost the grains that pressed on it (above, or beside it in the cylinder): it springs
// apart and falls back for tens of milliseconds, and timed so, its contacts fall (4.4 to 0.45-2.75
// per grain in 2,000 steps) and fewer contacts make a faster step: the sizes would not be like for
// like (docs/PERFORMANCE.md, "Against the grain count"). So a tile is settled alone, the bed is
// laid out of mirrored copies of the settled tile with its contact histories, and settled again
// where the copies meet (settled_bed).
constexpr double pack_column = 30e-3;  // the largest square the 44 mm cylinder holds, nearly

struct Bed {
  dem::Model model;
  dem::State grains;
};

// The reference scene's law in a box of planes (a floor, four sides) around `across` x `along`
// squares of side `side`, the first centred on the z axis, the floor at z = 0.
dem::Model boxed_model(const dem::State& grains, double side, int across, int along) {
  dem::ModelSpec spec = reference_spec();
  spec.gravity = dem::Vec3(0, 0, -9.81);
  const double lo = -0.5 * side, hi_x = lo + across * side, hi_y = lo + along * side;
  spec.planes = {{dem::Vec3(0, 0, 0), dem::Vec3::UnitZ(), 0, "floor"},
                 {dem::Vec3(lo, 0, 0), dem::Vec3::UnitX(), 0, "side"},
                 {dem::Vec3(hi_x, 0, 0), -dem::Vec3::UnitX(), 0, "side"},
                 {dem::Vec3(0, lo, 0), dem::Vec3::UnitY(), 0, "side"},
                 {dem::Vec3(0, hi_y, 0), -dem::Vec3::UnitY(), 0, "side"}};
  spec.domain = {dem::Vec3(lo, lo, 0) - dem::Vec3::Constant(2e-3), dem::Vec3(hi_x, hi_y, 0.1) + dem::Vec3::Constant(2e-3)};
  return dem::compile_model(spec, grains, "bench scaling");
}

// The grains of `source` wholly inside the centred square of side `side`, lowest first.
std::vector<std::size_t> lowest_in_square(const dem::State& source, double side) {
  std::vector<std::size_t> in_square;
  for (std::size_t i = 0; i < source.size(); ++i)
    if (std::max(std::abs(source.x[i].x()), std::abs(source.x[i].y())) + source.radius[i] < 0.5 * side) in_square.push_back(i);
  std::sort(in_square.begin(), in_square.end(), [&](std::size_t a, std::size_t b) { return source.x[a].z() < source.x[b].z(); });
  return in_square;
}

// One tile of `count` grains: the lowest of the pack's column (which holds `per_column`), or with
// `narrow`, the narrower square of the column's height that holds them; standing on the floor.
Bed column_tile(const dem::State& source, std::size_t count, std::size_t per_column, bool narrow) {
  // The square holding `count` by area holds fewer wholly inside: widened until it holds them.
  double side = narrow ? pack_column * std::sqrt(double(count) / double(per_column)) : pack_column;
  while (side < pack_column && lowest_in_square(source, side).size() < count) side = std::min(pack_column, 1.01 * side);
  const std::vector<std::size_t> lowest = lowest_in_square(source, side);
  if (lowest.size() < count)
    throw diefill::InputError("bench scaling", "--sizes", fmt::format("a tile of {} grains is more than the pack's column holds ({})", count, lowest.size()),
                              "Use the 50k LIGGGHTS pack (bench/scaling.sh prepares it)");
  const double z0 = source.x[lowest.front()].z() - source.radius[lowest.front()];
  dem::State tile;
  for (std::size_t k = 0; k < count; ++k)
    tile.add_sphere(std::int64_t(k), source.x[lowest[k]] - dem::Vec3(0, 0, z0), source.radius[lowest[k]], 2500, 0);
  return {boxed_model(tile, side, 1, 1), tile};
}

// `across` x `along` copies of the settled `tile` (side `side`) at a pitch of one tile, every other
// one mirrored, each with the tile's contact histories. Across a seam a grain that leaned on the
// tile's wall meets its own mirror image, which pushes it back as the wall did (twice as hard at the
// same overlap, by Hertz, so the pair gives way by a third of a wall overlap, under a micrometre),
// and their mirrored motions keep them from sliding on each other: the bed is laid out nearly at
// rest. (Copies side by side unmirrored met grains where there had been holes, slid into them and
// took 0.04-0.06 s to settle again at 50k-150k grains.)
Bed tiled_bed(const dem::State& tile, double side, int across, int along) {
  const dem::NeighbourList& listed = tile.neighbours;
  if (listed.row_start.size() != tile.size() + 1) throw std::logic_error("bench scaling: a settled tile comes with its neighbour list");
  dem::State bed;
  dem::NeighbourList& nl = bed.neighbours;
  nl.row_start.assign(1, 0);
  for (int t = 0; t < across * along; ++t) {
    // Mirrored in x and/or y: a vector's components flip, an axial vector's (angular velocity, a
    // torque) flip where the others' do not, and flip all but z where both flip.
    const int a = t % across, b = t / across;
    const dem::Vec3 flip(a % 2 ? -1 : 1, b % 2 ? -1 : 1, 1), shift(a * side, b * side, 0);
    const double handedness = flip.prod();
    const auto place = [&](const dem::Vec3& v) -> dem::Vec3 { return v.cwiseProduct(flip); };
    const auto turn = [&](const dem::Vec3& w) -> dem::Vec3 { return handedness * w.cwiseProduct(flip); };
    const auto first = std::int32_t(bed.size());
    for (std::size_t i = 0; i < tile.size(); ++i) {
      bed.add_sphere(std::int64_t(bed.size()), place(tile.x[i]) + shift, tile.radius[i], 2500, 0, place(tile.v[i]), turn(tile.w[i]));
      nl.row_start.push_back(nl.row_start.back() + listed.row_start[i + 1] - listed.row_start[i]);
    }
    for (const std::int32_t j : listed.partner) nl.partner.push_back(first + j);
    for (const dem::Vec3f& spring : listed.tangential) nl.tangential.push_back(place(spring.cast<double>()).cast<float>());
    for (const dem::Vec3f& torque : listed.rolling) nl.rolling.push_back(turn(torque.cast<double>()).cast<float>());
  }
  return {boxed_model(bed, side, across, along), bed};
}

// `bed` stepped until it rests by the LIGGGHTS preparation's own criterion (mean kinetic energy per
// grain below 1e-12 J, ../shared/bench/liggghts/in/prep.in), kept at `path` as a checkpoint with its
// contact histories, so that the timed steps go on from a bed at rest. Made once per bed (its
// positions, histories, model and the checkpoints' layout are the file's hash) in `cache`; under
// MPI by rank 0 alone.
dem::State settled_bed(const Bed& unsettled, const fs::path& cache, const std::string& name, const std::shared_ptr<dem::Exchange>& ranks) {
  const dem::Model& model = unsettled.model;
  const auto bytes = [](const auto& array) { return std::string_view(reinterpret_cast<const char*>(array.data()), array.size() * sizeof(array[0])); };
  const std::string key = diefill::sha256_hex(dem::checkpoint_layout() + model.hash + diefill::sha256_hex(bytes(unsettled.grains.x)) +
                                              diefill::sha256_hex(bytes(unsettled.grains.neighbours.tangential)));
  const fs::path path = cache / fmt::format("scaling_{}_{}.ckpt", name, key.substr(0, 16));
  if (!fs::exists(path) && (!ranks || ranks->rank() == 0)) {
    constexpr double at_rest_J = 1e-12, longest_s = 0.5;
    constexpr int steps_between_checks = 2000;
    dem::State bed = unsettled.grains;
    const double grains = double(bed.size());
    diefill::log::info("bench: settling a bed of {} grains (once; kept in {})", bed.size(), path.string());
    dem::initialize(model, bed);
    for (;;) {
      for (int n = 0; n < steps_between_checks; ++n)
        if (const dem::StepReport report = dem::step(model, bed); report.status != dem::StepStatus::ok)
          throw diefill::StabilityError(fmt::format("bench scaling: settling {} grains: {}", bed.size(), report.message), model.dt);
      const double per_grain = dem::kinetic_energy(bed) / grains;
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
      const std::size_t per_column = lowest_in_square(source, pack_column).size();
      for (std::size_t count : c.sizes) {
        Bed bed;
        if (count <= per_column) {
          bed = column_tile(source, count, per_column, true);
          bed.grains = settled_bed(bed, c.cache, fmt::format("tile_{}", count), ranks);
        } else {
          // Equal tiles filling a rectangle: a gap in it would be a slope for the bed to flow down.
          const std::size_t fewest = (count + per_column - 1) / per_column, across = std::size_t(std::ceil(std::sqrt(double(fewest))));
          const std::size_t along = (fewest + across - 1) / across, tiles = across * along;
          if (count % tiles != 0)
            throw diefill::InputError("bench scaling", "--sizes", fmt::format("{} grains make {} equal tiles only as a multiple of {}", count, tiles, tiles),
                                      fmt::format("Ask for {} or {} grains", count - count % tiles, count - count % tiles + tiles));
          Bed tile = column_tile(source, count / tiles, per_column, false);
          tile.grains = settled_bed(tile, c.cache, fmt::format("tile_{}", count / tiles), ranks);
          bed = tiled_bed(tile.grains, pack_column, int(across), int(along));
          if (!c.unsettled_beds) bed.grains = settled_bed(bed, c.cache, fmt::format("bed_{}", count), ranks);
        }
        results["cases"].push_back(time_case(fmt::format("scaling-{}", count), bed.model, bed.grains, c.steps, thread_counts, ranks));
        results["cases"].back()["bed_settled"] = count <= per_column || !c.unsettled_beds;
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
