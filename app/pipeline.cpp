#include "app/pipeline.hpp"

#include <fmt/core.h>
#include <omp.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "app/clump_stage.hpp"
#include "app/density_stage.hpp"
#include "app/run_loop.hpp"
#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "core/sha256.hpp"
#include "core/timer.hpp"
#include "dem/checkpoint.hpp"
#include "dem/insert.hpp"
#include "dem/io.hpp"
#include "dem/neighbours.hpp"
#include "dem/step.hpp"
#include "mesh/die.hpp"
#include "mesh/exact.hpp"
#include "mesh/shapes.hpp"

namespace app {

namespace fs = std::filesystem;
using diefill::InputError;
using dem::Vec3;

namespace {

// Where the shoe goes: its inner rectangle centred at (x, y_centre) on the table.
struct ShoePlan {
  double length, width;        // inner [m] (width after trimming)
  double x_start, x_end;       // shoe centre at the start and the end of a pass
  double y_centre;
  double t_motion;             // duration of the whole motion [s]
  dem::Motion motion;          // of the shoe's frame (origin at its inner centre, on the table)
};

// Accelerate to v, cruise, decelerate to rest over `distance` (signed along x).
void add_stroke(dem::Motion& m, double distance, double v, double a) {
  const double sign = distance < 0 ? -1 : 1, d = std::abs(distance);
  double ta = v / a, cruise = d - v * ta;
  if (cruise < 0) ta = std::sqrt(d / a), cruise = 0;  // never reaches v
  m.segments.push_back({ta, Vec3(sign * a, 0, 0)});
  if (cruise > 0) m.segments.push_back({cruise / (a * ta), Vec3::Zero()});  // a ta = v
  m.segments.push_back({ta, Vec3(-sign * a, 0, 0)});
}

ShoePlan plan_shoe(const PipelineScene& s, const mesh::Box& die_box, double table_z) {
  ShoePlan p;
  p.length = s.shoe_length;
  const double die_width = die_box.size().y();
  p.width = s.trim_width ? std::min(s.shoe_width, die_width + 2 * s.side_margin) : s.shoe_width;
  if (p.width < die_width + 2 * s.side_margin) {
    diefill::log::warn("the shoe ({:.4g} mm wide) does not cover the die ({:.4g} mm) with its side margin; widened to {:.4g} mm",
                       s.shoe_width * 1e3, die_width * 1e3, (die_width + 2 * s.side_margin) * 1e3);
    p.width = die_width + 2 * s.side_margin;
  }
  p.y_centre = 0.5 * (die_box.lo.y() + die_box.hi.y());
  p.x_start = die_box.lo.x() - s.start_gap - 0.5 * p.length;
  p.x_end = die_box.hi.x() + s.end_gap + 0.5 * p.length;
  p.motion.start_position = Vec3(p.x_start, p.y_centre, table_z);  // raised by the clearance once grains are sized
  for (int pass = 0; pass < s.passes; ++pass) {
    add_stroke(p.motion, p.x_end - p.x_start, s.speed, s.acceleration);
    if (s.dwell > 0) p.motion.segments.push_back({s.dwell, Vec3::Zero()});
    if (s.return_stroke) add_stroke(p.motion, p.x_start - p.x_end, s.speed, s.acceleration);
  }
  p.t_motion = 0;
  for (const auto& seg : p.motion.segments) p.t_motion += seg.duration;
  return p;
}

// Upper bound of the radius of the largest sphere the cavity holds below the table: the distance
// to the die is 1-Lipschitz, so the true maximum exceeds the sampled one by at most half a grid
// diagonal. Beyond the field's band, which reads as the band there, the exact distance.
double largest_inscribed_radius_bound(const mesh::WallField& die, const mesh::ExactSurface& exact, const mesh::Box& cavity,
                                      double table_z, double spacing) {
  const Vec3 size = cavity.size();
  spacing = std::max(spacing, size.maxCoeff() / 64);
  const int nx = int(size.x() / spacing) + 1, ny = int(size.y() / spacing) + 1, nz = int((table_z - cavity.lo.z()) / spacing) + 1;
  double best = -std::numeric_limits<double>::infinity();
#pragma omp parallel for collapse(2) reduction(max : best) schedule(static)
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) {
        const Vec3 p = cavity.lo + spacing * Vec3(i + 0.5, j + 0.5, k + 0.5);
        const double near = die.signed_distance(p);
        best = std::max(best, near >= die.free_band ? exact.distance(p) : near);
      }
  return best + 0.5 * std::sqrt(3.0) * spacing;
}

// A grain once: a free sphere, or a clump by its centre of mass.
struct GrainRef {
  Vec3 centre;
  bool active;
  std::int64_t body;  // -1: the free sphere `index`
  std::size_t index;
};

std::vector<GrainRef> grains_of(const dem::State& s) {
  std::vector<GrainRef> grains;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.body[i] < 0) grains.push_back({s.x[i], s.active[i] != 0, -1, i});
  for (std::size_t b = 0; b < s.bodies.size(); ++b) grains.push_back({s.bodies.x[b], s.bodies.active[b] != 0, std::int64_t(b), b});
  return grains;
}

// The grain's volume as spheres for binning: a clump's members weighted so that they add up to
// the real grain's volume, counted once however much they overlap.
void add_volume(const dem::State& s, const GrainRef& g, std::vector<post::Grain>& out) {
  if (g.body < 0) {
    out.push_back({s.x[g.index], s.radius[g.index], 1.0});
    return;
  }
  const dem::Bodies& b = s.bodies;
  const auto first = std::size_t(b.member_start[g.index]), last = std::size_t(b.member_start[g.index + 1]);
  double members = 0;
  for (std::size_t m = first; m < last; ++m) members += 4.0 / 3.0 * std::numbers::pi * std::pow(s.radius[std::size_t(b.member[m])], 3);
  for (std::size_t m = first; m < last; ++m) {
    const std::size_t i = std::size_t(b.member[m]);
    out.push_back({s.x[i], s.radius[i], b.volume[g.index] / members});
  }
}

// The scene less what happens after the shoe has settled (its motion, the die's settling, the
// density field, the output): the key of the cached settled shoe.
PipelineScene settling_part(const PipelineScene& s) {
  PipelineScene part = s;
  const PipelineScene defaults;
  part.speed = defaults.speed, part.acceleration = defaults.acceleration, part.end_gap = defaults.end_gap;
  part.dwell = defaults.dwell, part.passes = defaults.passes, part.return_stroke = defaults.return_stroke;
  part.die_settle_time = defaults.die_settle_time;
  part.density_voxel = defaults.density_voxel, part.density_method = defaults.density_method;
  part.out = defaults.out, part.snapshot_every = defaults.snapshot_every, part.threads = defaults.threads;
  part.source = defaults.source;
  return part;
}

}  // namespace

DieRun run_die_fill(const PipelineScene& s, const fs::path& die_mesh, bool resume) {
  diefill::Stopwatch wall_clock;
  if (s.threads > 0) omp_set_num_threads(s.threads);
  const int powder = material_named(s.spec, "powder"), steel = material_named(s.spec, "steel");
  double diameter = s.grain_diameter();
  const double spread = s.diameter_spread;

  // 1. The die: cavity, tool and SDF over a table as long as the shoe's travel.
  const auto die_options_for = [&](double grain_diameter) {
    const double r = 0.5 * grain_diameter * (1 + spread);
    mesh::DieOptions o = mesh::die_options_for_grains(r, 0.5 * r, s.die_voxel_fraction * r);
    o.unit = mesh::parse_unit(s.die_units, "die.units");
    o.role = mesh::parse_role(s.die_role, "die.role");
    return o;
  };
  mesh::DieOptions die_options = die_options_for(diameter);
  if (die_options.role != mesh::WallRole::cavity)
    throw InputError(die_mesh.string(), "die.role", "the pipeline fills a cavity", "Give the cavity mesh (role \"cavity\")");
  const mesh::ImportResult preview = mesh::import_mesh(die_mesh, {die_options.unit});
  const mesh::Box box = mesh::bounding_box(preview.mesh);
  const double table_z = box.hi.z();
  // Coarser grains when the powder would need too many: the shoe's powder over the die.
  ShoePlan plan = plan_shoe(s, box, table_z);
  const double grain_volume = std::numbers::pi / 6 * diameter * diameter * diameter;
  double estimate = plan.length * plan.width * s.fill_height * 0.6 / grain_volume;
  if (estimate > double(s.max_grains)) {
    const double scale = std::cbrt(estimate / double(s.max_grains));
    diefill::log::warn("{}: {:.0f} grains of {:.3g} mm would exceed powder.max_grains = {}; using {:.3g} mm grains "
                       "(coarse graining {:.3g} instead of {:.3g})",
                       die_mesh.string(), estimate, diameter * 1e3, s.max_grains, diameter * scale * 1e3,
                       s.coarse_graining * scale, s.coarse_graining);
    diameter *= scale;
    estimate = double(s.max_grains);
    die_options = die_options_for(diameter);
  }
  const double r_max = 0.5 * diameter * (1 + spread);
  plan.motion.start_position.z() = table_z + s.clearance * r_max;
  const double margin = 2e-3 + 2 * r_max;
  die_options.table = mesh::TableExtent{plan.x_start - 0.5 * plan.length - s.shoe_wall - margin,
                                        plan.y_centre - 0.5 * plan.width - s.shoe_wall - margin,
                                        plan.x_end + 0.5 * plan.length + s.shoe_wall + margin,
                                        plan.y_centre + 0.5 * plan.width + s.shoe_wall + margin, 2e-3};
  const fs::path cache = s.out / ".cache";
  const mesh::PreparedDie die = mesh::prepare_die(die_mesh, die_options, cache);
  const fs::path dir = s.out / die.name;
  fs::create_directories(dir);

  // 2. The shoe: a rectangular tube, its own SDF, moving rigidly on the table.
  //    A shoe from a mesh is a tool in its own frame: origin at the inner centre, on the table.
  std::shared_ptr<const mesh::WallField> shoe_field;
  if (!s.shoe_mesh.empty()) {
    // Voxels as mesh::contact_wall_field's: the query is exact, the voxels only find candidates.
    mesh::DieOptions shoe_options = mesh::die_options_for_grains(r_max, 0.5 * r_max, 0.5 * r_max);
    shoe_options.unit = die_options.unit;
    shoe_options.role = mesh::WallRole::tool;
    const mesh::PreparedDie shoe_die = mesh::prepare_die(s.shoe_mesh, shoe_options, cache);
    shoe_field = std::make_shared<const mesh::WallField>(shoe_die.sdf.wall_field(shoe_die.solid));
  } else {
    shoe_field = std::make_shared<const mesh::WallField>(
        mesh::contact_wall_field(mesh::shoe_solid(plan.length, plan.width, s.shoe_height, s.shoe_wall), r_max));
  }
  auto die_field = std::make_shared<const mesh::WallField>(die.sdf.wall_field(die.solid));
  // Grains too coarse for the cavity: refused when none can enter it; warned when it is narrower
  // than a few grains, where the wall layer is most of the part (PHYSICS.md §4).
  const double inscribed = largest_inscribed_radius_bound(*die_field, mesh::ExactSurface(die.solid), box, table_z, 0.1 * r_max);
  if (inscribed < r_max)
    throw InputError(die_mesh.string(), "powder.coarse_graining",
                     fmt::format("grains up to {:.3g} mm across cannot enter the cavity: the largest sphere it holds is at most "
                                 "{:.3g} mm across",
                                 2 * r_max * 1e3, 2 * inscribed * 1e3),
                     "Lower powder.coarse_graining (or raise powder.max_grains, which coarsens grains for large shoes)");
  if (inscribed < 1.5 * diameter)
    diefill::log::warn("{}: the cavity holds no sphere wider than {:.3g} mm, under three grains of {:.3g} mm: the density "
                       "there is mostly wall layer; lower powder.coarse_graining",
                       die.name, 2 * inscribed * 1e3, diameter * 1e3);

  dem::ModelSpec spec = coarse_grained_spec(s.spec, diameter / s.particle_diameter);
  // The collision time must resolve the fastest impact: a grain falling the die's depth onto the
  // floor, plus the shoe's speed.
  const double impact = std::sqrt(2 * spec.gravity.norm() * box.size().z()) + s.speed;
  if (impact > spec.max_impact_speed) {
    diefill::log::info("{}: impacts reach {:.3g} m/s in this die; time step set for them (simulation.max_impact_speed was {:.3g})",
                       die.name, impact, spec.max_impact_speed);
    spec.max_impact_speed = impact;
  }
  spec.domain = {Vec3(die_options.table->x_min, die_options.table->y_min, box.lo.z() - 1e-3),
                 Vec3(die_options.table->x_max, die_options.table->y_max, table_z + s.shoe_height + 5e-3)};
  spec.meshes.push_back(dem::fixed_mesh_wall(die_field, steel, "die"));
  dem::MeshWall shoe = dem::fixed_mesh_wall(shoe_field, steel, "shoe");
  shoe.motion.start_position = plan.motion.start_position;
  // Cut at the table, so that a grain pinched between the table (or the rim) and the shoe
  // overlaps them by at most half the stop limit together: the strike-off never stops a run
  // (cut at half a radius, a pinched grain reached the limit in one run in ten at 1.6 mm).
  shoe.cut_z = table_z;
  shoe.cut_fraction = 1 - 0.5 * spec.stop_overlap;
  spec.meshes.push_back(shoe);

  // 3. Fill the shoe and let the powder settle, at rest at its start; cached by everything that
  //    shapes it, and always resumed from the cached positions so that a cached and a fresh run
  //    give the same result.
  const std::string shoe_key = diefill::sha256_hex(fmt::format(
      "v2;{};{};{:a};{:a};{:a};{:a};{:a};{:a};{:a};{:a};{};{}", die.cache_key, describe(settling_part(s)), diameter, plan.length,
      plan.width, plan.x_start, plan.y_centre, s.fill_height, s.shoe_settle_time, table_z, s.seed, powder));
  const fs::path settled = cache / ("shoe-" + shoe_key + ".csv");
  const double density = spec.materials[std::size_t(powder)].density;
  const bool clumps = !s.shape_mesh.empty();
  std::optional<mesh::ClumpTemplate> shape;
  if (clumps)
    shape = build_clump({s.shape_mesh, mesh::parse_unit(s.shape_units, "powder.shape.units"), s.shape_tolerance, 64, s.seed});
  dem::State state;
  // Clumps are settled afresh each run: the particles file does not hold their poses.
  if (clumps || !fs::exists(settled)) {
    dem::State fill;
    dem::InsertRegion region;
    const double inset = r_max + 1e-6;
    region.box = {Vec3(plan.x_start - 0.5 * plan.length + inset, plan.y_centre - 0.5 * plan.width + inset, table_z + inset),
                  Vec3(plan.x_start + 0.5 * plan.length - inset, plan.y_centre + 0.5 * plan.width - inset,
                       table_z + std::min(s.shoe_height - inset, s.fill_height * 0.6 / 0.38 + 2 * r_max))};
    dem::InsertRequest request;
    request.count = std::size_t(estimate);
    request.radius = 0.5 * diameter;
    request.radius_spread = spread;
    request.material = powder;
    request.density = density;
    request.seed = s.seed;
    request.max_solid_fraction = 0.45;
    const std::size_t inserted =
        clumps ? dem::insert_clumps(fill, region, *shape, diameter / shape->equivalent_diameter_m, request.count, powder,
                                    density, s.seed)
               : dem::insert_spheres(fill, region, request);
    diefill::log::info("{}: settling {} {} of {:.3g} mm in the shoe ({:.3g} x {:.3g} mm{})", die.name, inserted,
                       clumps ? fmt::format("clumps of {} spheres", shape->spheres.size()) : "grains", diameter * 1e3,
                       plan.length * 1e3, plan.width * 1e3, clumps ? "" : ", once; cached");
    // The settling shoe sees no fall into the die: the scene's time step, whatever the die and
    // the shoe's speed, so that runs differing in those reuse it.
    dem::ModelSpec settle_spec = spec;
    settle_spec.max_impact_speed = s.spec.max_impact_speed;
    const dem::Model settle_model = dem::compile_model(settle_spec, fill, s.source);
    dem::initialize(settle_model, fill);
    LoopOptions loop;
    loop.until = s.shoe_settle_time;
    loop.label = die.name + ": settling the shoe";
    // Interrupted while settling: nothing is cached (a half-settled shoe must never be reused);
    // a resumed run settles afresh.
    if (run_until(settle_model, fill, loop).interrupted) {
      DieRun stopped;
      stopped.die = die.name;
      stopped.dir = dir;
      stopped.interrupted = true;
      return stopped;
    }
    if (clumps) state = std::move(fill);
    else dem::write_particles_csv(fill, settled);
  }
  // A cached and a fresh run start from the same numbers: the file's.
  if (!clumps) state = dem::read_particles_csv(settled, powder, density);
  for (Vec3& v : state.v) v.setZero();
  for (Vec3& w : state.w) w.setZero();
  for (Vec3& v : state.bodies.v) v.setZero();
  for (Vec3& l : state.bodies.l) l.setZero();
  state.time = 0;  // the shoe's motion starts now
  state.step = 0;
  const std::size_t inserted = grains_of(state).size();

  // 4. Move the shoe, then let the die settle.
  spec.meshes[1].motion = plan.motion;
  const dem::Model model = dem::compile_model(spec, state, s.source);
  const fs::path checkpoint = dir / "checkpoint.bin";
  if (resume && fs::exists(checkpoint)) {
    state = dem::read_checkpoint(model, checkpoint);
    diefill::log::info("{}: resumed at t = {:.6g} s", die.name, state.time);
  } else {
    dem::initialize(model, state);
  }
  auto in_cavity = [&](const dem::State& st) {
    std::size_t n = 0;
    for (const GrainRef& g : grains_of(st)) n += g.active && g.centre.z() < table_z;
    return n;
  };
  LoopOptions loop;
  loop.until = plan.t_motion + s.die_settle_time;
  loop.label = die.name + ": filling";
  loop.checkpoint = checkpoint;
  int snapshot = 0;
  if (s.snapshot_every > 0) {
    loop.output_every = s.snapshot_every;
    loop.output = [&](const dem::State& st) { dem::write_vtu(st, dir / fmt::format("snapshot_{:05d}.vtu", snapshot++)); };
  }
  loop.detail = [&](const dem::State& st) { return fmt::format("{} grains in the cavity", in_cavity(st)); };
  const LoopResult result = run_until(model, state, loop);
  DieRun run;
  run.die = die.name;
  run.dir = dir;
  if (result.interrupted) {
    run.interrupted = true;
    return run;
  }
  fs::remove(checkpoint);

  // 5. Count every grain.
  const Vec3 shoe_centre = plan.motion.position(state.time);
  std::size_t cavity = 0, in_shoe = 0, elsewhere = 0;
  // A grain that left the domain above the table spilled over its edge beside the shoe: counted,
  // and harmless to the fill. One that left below it went through the die: a leak.
  std::size_t lost = 0, leaked = 0;
  Vec3 leak;
  std::vector<post::Grain> grains;
  for (const GrainRef& g : grains_of(state)) {
    if (!g.active) {
      ++lost;
      if (g.centre.z() < table_z) leak = g.centre, ++leaked;
      continue;
    }
    const Vec3& x = g.centre;
    if (x.z() < table_z) {
      ++cavity;
      add_volume(state, g, grains);
    } else if (std::abs(x.x() - shoe_centre.x()) < 0.5 * plan.length && std::abs(x.y() - shoe_centre.y()) < 0.5 * plan.width) {
      ++in_shoe;
    } else {
      ++elsewhere;
    }
  }
  if (leaked > 0)
    throw InputError(die_mesh.string(), "particles.lost",
                     fmt::format("{} grains left the simulated domain below the die table, through the die (one at ({:.3g}, "
                                 "{:.3g}, {:.3g}) mm)",
                                 leaked, leak.x() * 1e3, leak.y() * 1e3, leak.z() * 1e3),
                     "Check the die mesh for holes or walls thinner than its voxels");
  if (lost > 0)
    diefill::log::warn("{}: {} grains spilled over the die table's edge beside the shoe; counted in report.json "
                       "(particles.lost), not in the fill",
                       die.name, lost);

  // 6. Density, report, pictures: staged, so that a failure keeps the earlier outputs.
  diefill::StagingFolder out(dir);
  DensitySettings ds;
  ds.voxel_m = s.density_voxel > 0 ? s.density_voxel : 2 * diameter;
  ds.method = s.density_method;
  nlohmann::json fill_json;
  if (!grains.empty()) {
    const DensityResult field = compute_density(grains, die, *die_field, density, ds, die.name);
    auto metadata = [&](DensityResult r) {
      r.field.metadata["coarse_graining"] = fmt::format("{}", diameter / s.particle_diameter);
      r.field.metadata["die"] = die.name;
      return r;
    };
    const DensityResult tagged = metadata(field);
    write_density(tagged, out.path());
    fill_json = statistics_json(field.stats);
  } else {
    diefill::log::warn("{}: no grain entered the cavity; no density field", die.name);
    fill_json = {{"mass_kg", 0.0}, {"fill_ratio", 0.0}};
  }
  dem::write_particles_csv(state, out / "particles.csv");
  dem::write_vtu(state, out / "final.vtu");
  diefill::write_file_atomic(out / "scene.toml", describe(s));
  // Summed from the same weighted members the density binning gets, so that the report shows
  // the volume the field holds (a clump's true volume, not its overlapping spheres').
  double grain_volume_total = 0;
  {
    std::vector<post::Grain> all;
    for (const GrainRef& g : grains_of(state)) add_volume(state, g, all);
    for (const post::Grain& g : all) grain_volume_total += g.weight * 4.0 / 3.0 * std::numbers::pi * std::pow(g.radius, 3);
  }
  const double steps = double(result.steps);
  nlohmann::json report = {
      {"die",
       {{"name", die.name},
        {"source", die.source},
        {"sha256", die.sha256},
        {"cavity_volume_m3", die.after.volume_m3},
        {"triangles", die.before.triangles},
        {"repaired", !die.actions.empty()},
        {"repairs", die.actions},
        {"table_z_m", table_z}}},
      {"powder",
       {{"grains", inserted},
        {"grain_volume_m3", grain_volume_total},
        {"material_density", density},
        {"coarse_graining", diameter / s.particle_diameter},
        {"grain_diameter_m", diameter},
        {"shape", clumps ? s.shape_mesh : "sphere"},
        {"spheres_per_grain", clumps ? shape->spheres.size() : std::size_t{1}}}},
      {"shoe", {{"length_m", plan.length}, {"width_m", plan.width}, {"speed_m_s", s.speed}, {"passes", s.passes}}},
      {"fill", fill_json},
      {"particles", {{"inserted", inserted}, {"in_cavity", cavity}, {"in_shoe", in_shoe}, {"elsewhere", elsewhere}, {"lost", lost}}},
      {"timing",
       {{"wall_s", wall_clock.seconds()},
        {"steps", result.steps},
        {"dt_s", model.dt},
        {"particle_steps_per_s", steps * double(state.size()) / std::max(1e-9, result.wall_s)},
        {"stages", stage_times_json(result.times)}}},
      {"stability",
       {{"max_overlap_rel", state.counters.max_overlap_rel},
        {"checks_passed", true},
        {"warnings", diefill::log::take_warnings()}}}};
  diefill::write_file_atomic(out / "report.json", report.dump(2) + "\n");
  out.commit();
  run.report = report;
  diefill::log::info("{}: {} of {} grains in the cavity, fill ratio {:.3f}, mean solid fraction {:.3f} -> {}", die.name, cavity,
                     inserted, fill_json.value("fill_ratio", 0.0), fill_json.value("solid_fraction_mean", 0.0), dir.string());
  return run;
}

}  // namespace app
