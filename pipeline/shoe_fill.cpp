#include "pipeline/shoe_fill.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <stdexcept>

#include "core/log.hpp"
#include "core/sha256.hpp"
#include "dem/distributed.hpp"
#include "dem/insert.hpp"
#include "dem/io.hpp"
#include "dem/step.hpp"
#include "pipeline/clump_stage.hpp"
#include "pipeline/run_loop.hpp"
#include "pipeline/shoe_source_hash.hpp"
#include "scene/physics_keys.hpp"

namespace pipeline {

namespace fs = std::filesystem;
using dem::Vec3;

namespace {

constexpr double insertion_solid_fraction = 0.45;  // stop a round's insertion at this fill of its box

struct Insertion {
  const scene::PipelineScene& scene;
  const FillWalls& walls;
  const GrainSizing& grains;
  const ShoePlan& shoe;
  double table_z;
  std::optional<geometry::ClumpTemplate> clump;
  std::shared_ptr<dem::Exchange> ranks;  // null: one process
};

// The powder already in the shoe, over every rank of a split run.
struct Bed {
  double top;             // its highest point (the table when empty) [m]
  std::int64_t grains;
  std::int64_t next_id;   // the first id not taken
};

Bed bed_of(const Insertion& in, const dem::State& bed) {
  Bed b{in.table_z, std::int64_t(bed.owned()), 0};
  for (std::size_t i = 0; i < bed.owned(); ++i)
    b.top = std::max(b.top, bed.x[i].z() + bed.radius[i]), b.next_id = std::max(b.next_id, bed.id[i] + 1);
  if (bed.exchange)
    b = {bed.exchange->max(b.top), bed.exchange->sum(b.grains), std::int64_t(bed.exchange->max(double(b.next_id)))};
  return b;
}

// The box above the powder already in the shoe (from the table at first), inside its walls, as
// high as `count` more grains need at the jamming fraction of random insertion (about 0.38 of
// the poured 0.6): grains dropped from no higher than that cannot be thrown out of the shoe.
dem::InsertRegion space_above_bed(const Insertion& in, const Bed& bed, std::size_t count) {
  const double inset = in.grains.r_max + 1e-6;
  const double bed_height = bed.grains == 0 ? in.scene.shoe.fill_height
                                            : double(count) * std::numbers::pi / 6 * std::pow(in.grains.diameter, 3) /
                                                  (0.6 * in.shoe.length * in.shoe.width);
  const double top = std::min(in.table_z + in.scene.shoe.height - inset, bed.top + bed_height * 0.6 / 0.38 + 2 * in.grains.r_max);
  dem::InsertRegion region;
  region.box = {Vec3(in.shoe.x_start - 0.5 * in.shoe.length + inset, in.shoe.y_centre - 0.5 * in.shoe.width + inset, bed.top + inset),
                Vec3(in.shoe.x_start + 0.5 * in.shoe.length - inset, in.shoe.y_centre + 0.5 * in.shoe.width - inset, top)};
  return region;
}

std::size_t insert_round(const Insertion& in, dem::State& bed, std::size_t count, int round) {
  const Bed before = bed_of(in, bed);
  const dem::InsertRegion region = space_above_bed(in, before, count);
  if (region.box.hi.z() <= region.box.lo.z()) return 0;
  const std::uint64_t seed = in.scene.seed + std::uint64_t(round) * 7919;  // round 0: the scene's seed, as always
  const double density = in.walls.spec.materials[std::size_t(in.walls.powder)].density;
  const auto draw = [&](dem::State& into) {
    if (in.clump)
      return dem::insert_clumps(into, region, *in.clump, in.grains.diameter / in.clump->equivalent_diameter_m, count,
                                in.walls.powder, density, seed, before.next_id);
    dem::InsertRequest request;
    request.count = count;
    request.radius = 0.5 * in.grains.diameter;
    request.radius_spread = in.scene.powder.diameter_spread;
    request.material = in.walls.powder;
    request.density = density;
    request.seed = seed;
    request.first_id = before.next_id;
    request.max_solid_fraction = insertion_solid_fraction;
    return dem::insert_spheres(into, region, request);
  };
  if (!bed.exchange) return draw(bed);
  // Split over ranks, every rank draws the same new grains (the box lies above the bed, so the
  // grains below cannot change a draw) and takes its share of them.
  dem::State fresh;
  const std::size_t added = draw(fresh);
  dem::add_share(bed, fresh);
  return added;
}

// Settles the bed for shoe.settle_time at the scene's time step (the settling shoe sees no fall
// into the die, so runs differing in the die's depth or the shoe's speed reuse it). False on Ctrl-C.
bool settle(const Insertion& in, dem::State& bed, const std::string& label, double& particle_steps) {
  dem::ModelSpec spec = in.walls.spec;
  spec.max_impact_speed = in.scene.spec.max_impact_speed;
  const dem::Model model = dem::compile_model(spec, bed, in.scene.source);
  bed.time = 0;
  bed.step = 0;
  dem::initialize(model, bed);
  LoopOptions loop;
  loop.until = in.scene.motion.shoe_settle_time;
  loop.label = label;
  loop.max_steps = in.scene.max_steps;
  const LoopResult result = run_until(model, bed, loop);
  particle_steps += double(result.steps) * double(bed.exchange ? bed.exchange->sum(std::int64_t(bed.owned())) : std::int64_t(bed.size()));
  return !result.interrupted;
}

std::optional<SettledShoe> settle_afresh(const Insertion& in, const std::string& die_name) {
  SettledShoe out;
  out.state.exchange = in.ranks;
  out.requested = in.grains.count;
  for (int round = 0; round < max_insertion_rounds && out.inserted < out.requested; ++round) {
    const std::size_t added = insert_round(in, out.state, out.requested - out.inserted, round);
    if (added == 0) break;
    out.inserted += added;
    diefill::log::info("{}: settling {} {} of {:.3g} mm in the shoe ({:.3g} x {:.3g} mm{})", die_name, out.inserted,
                       in.clump ? fmt::format("clumps of {} spheres", in.clump->spheres.size()) : "grains",
                       in.grains.diameter * 1e3, in.shoe.length * 1e3, in.shoe.width * 1e3, in.clump ? "" : ", once; cached");
    // Interrupted while settling: nothing is cached (a half-settled shoe must never be reused).
    if (!settle(in, out.state, die_name + ": settling the shoe", out.particle_steps)) return std::nullopt;
  }
  if (out.inserted < out.requested)
    diefill::log::warn("{}: the shoe holds {} of the {} grains that fill it to shoe.fill_height = {:.4g} mm; raise shoe.height or "
                       "lower shoe.fill_height",
                       die_name, out.inserted, out.requested, in.scene.shoe.fill_height * 1e3);
  return out;
}

// A cached and a fresh run start from the same numbers: the file's, at rest.
void rest(dem::State& state) {
  for (Vec3& v : state.v) v.setZero();
  for (Vec3& w : state.w) w.setZero();
  for (Vec3& v : state.bodies.v) v.setZero();
  for (Vec3& l : state.bodies.l) l.setZero();
  state.time = 0;
  state.step = 0;
}

// Every rank builds the clump template itself (from the same mesh and seed) and keeps its share
// of clumps drawn from it: should the builds ever differ, the shares would not fit together.
void expect_same_template_on_every_rank(const geometry::ClumpTemplate& clump, dem::Exchange& ranks) {
  double fingerprint = clump.mesh_volume_m3;
  for (const geometry::ClumpSphere& sphere : clump.spheres) fingerprint += sphere.radius + sphere.centre.sum() * 0.5;
  if (ranks.max(fingerprint) != -ranks.max(-fingerprint))
    throw std::logic_error("the ranks built different clump templates from one grain mesh");
}

}  // namespace

std::string settled_shoe_key(const scene::PipelineScene& s, const SettledShoeInputs& in, std::string_view dem_source_hash) {
  // What makes a shoe: the code (this file's and the DEM's sources), the die, the settling keys,
  // the materials, the grains and the shoe. A smoke run's shoe (PipelineScene::max_steps) is not
  // settled: it is never a real run's.
  return diefill::sha256_hex(fmt::format("settled shoe;{};{};{};{}{};{:a};{:a};{};{:a};{:a};{:a};{:a};{:a};{};{}",
                                         DIEFILL_SHOE_SOURCE_HASH, dem_source_hash, in.die_cache_key,
                                         scene::shaping_values(scene::pipeline_keys(), scene::Shapes::settling, s),
                                         scene::describe_materials(s.spec), in.grains.diameter, in.grains.r_max, in.grains.count,
                                         in.shoe.length, in.shoe.width, in.shoe.x_start, in.shoe.y_centre, in.table_z, in.powder,
                                         s.max_steps));
}

std::optional<SettledShoe> fill_and_settle_shoe(const scene::PipelineScene& s, const FillWalls& walls, const GrainSizing& grains,
                                                const ShoePlan& shoe, double table_z, const std::shared_ptr<dem::Exchange>& ranks) {
  Insertion in{s, walls, grains, shoe, table_z, std::nullopt, ranks};
  // Clumps are settled afresh each run: the particles file does not hold their poses.
  if (!s.powder.shape_mesh.empty()) {
    in.clump = build_clump({s.powder.shape_mesh, s.powder.shape_units, s.powder.shape_tolerance, 64, s.seed});
    if (ranks) expect_same_template_on_every_rank(*in.clump, *ranks);
    std::optional<SettledShoe> settled = settle_afresh(in, walls.die.name);
    if (settled) rest(settled->state);
    return settled;
  }
  const std::string key = settled_shoe_key(s, {walls.die.cache_key, grains, shoe, table_z, walls.powder}, dem::source_hash());
  const fs::path file = walls.cache / ("shoe-" + key + ".csv");
  SettledShoe out;
  // Split over ranks, rank 0 looks and every rank goes by what it saw.
  out.from_cache = ranks ? ranks->max(ranks->rank() == 0 && fs::exists(file) ? 1.0 : 0.0) > 0 : fs::exists(file);
  if (!out.from_cache) {
    const std::optional<SettledShoe> settled = settle_afresh(in, walls.die.name);
    if (!settled) return std::nullopt;
    out.particle_steps = settled->particle_steps;
    fs::create_directories(walls.cache);
    dem::with_whole_state(settled->state, [&](const dem::State& whole) { dem::write_particles_csv(whole, file); });
  }
  // Every run, cached or not, split or not, starts from the file's numbers; split, each rank reads
  // its share of them (the grains share_of would keep).
  const dem::RowShare share = ranks ? dem::RowShare{ranks->rank(), ranks->ranks()} : dem::RowShare{};
  dem::run_and_agree(ranks.get(), true, [&] {
    out.state = dem::read_particles_csv(file, walls.powder, walls.spec.materials[std::size_t(walls.powder)].density, share);
  });
  out.state.exchange = ranks;
  out.requested = grains.count;
  out.inserted = std::size_t(ranks ? ranks->sum(std::int64_t(out.state.size())) : std::int64_t(out.state.size()));
  rest(out.state);
  return out;
}

}  // namespace pipeline
