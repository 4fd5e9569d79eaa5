// `diefill study stability`: where each method fails, and whether diefill says so. Four probes,
// each swept across its limit:
//  - the time step against the stable limit (min of the Rayleigh and Hertz times): a pack dropped
//    into a box;
//  - the die's voxel against the grain radius: grains dropped into the ring die;
//  - a wall's travel per step against half the neighbour skin: a block pushed through a bed;
//  - the grain diameter against the ring's annulus width: the whole pipeline.
// Each run ends one of four ways: it ran and its result checks out; a stability check stopped
// it (exit 3); a check refused it before it ran (exit 2); or it ran and the result is wrong
// without any check noticing — the outcome this study exists to rule out.
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <functional>

#include "pipeline/die_fill.hpp"
#include "studies/studies.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "dem/step.hpp"
#include "dem/walls.hpp"
#include "mesh/die.hpp"
#include "mesh/exact.hpp"
#include "mesh/import.hpp"
#include "mesh/shapes.hpp"

namespace studies {

namespace {

using dem::Vec3;

enum class Outcome { passed, stopped, refused, wrong };
constexpr const char* outcome_names[] = {"ran, checks passed", "stopped by a stability check", "refused before running",
                                         "ran, wrong and not caught"};

struct Probe {
  std::string name, parameter;
  double ratio;
  Outcome outcome;
  std::string detail;  // the check's message, or what the result showed
};

// Runs `body`, which returns what its result showed (empty when the result checks out).
Probe probe(const std::string& name, const std::string& parameter, double ratio, const std::function<std::string()>& body) {
  Probe p{name, parameter, ratio, Outcome::passed, ""};
  try {
    p.detail = body();
    if (!p.detail.empty()) p.outcome = Outcome::wrong;
  } catch (const diefill::StabilityError& e) {
    p.outcome = Outcome::stopped, p.detail = e.what();
  } catch (const diefill::InputError& e) {
    p.outcome = Outcome::refused, p.detail = e.what();
  }
  diefill::log::info("stability: {} = {:.3g}: {}{}", parameter, ratio, outcome_names[int(p.outcome)],
                     p.detail.empty() ? "" : " (" + p.detail + ")");
  return p;
}

dem::PlaneWall plane(const Vec3& point, const Vec3& normal, int material) { return {point, normal, material, "box"}; }

// Floor and four sides of a box [-half, half]² from z = 0.
std::vector<dem::PlaneWall> box_planes(double half, int material) {
  return {plane(Vec3::Zero(), Vec3::UnitZ(), material), plane(Vec3(-half, 0, 0), Vec3::UnitX(), material),
          plane(Vec3(half, 0, 0), -Vec3::UnitX(), material), plane(Vec3(0, -half, 0), Vec3::UnitY(), material),
          plane(Vec3(0, half, 0), -Vec3::UnitY(), material)};
}

// The judge of a run that no check stopped, from the whole run, not its last step: nothing lost,
// no overlap at any step beyond the probe's physical bound, and no energy gained beyond what
// gravity and the walls gave, by more than a thousandth of the energy scale Σ m g r, at any of the
// monitor's checks. The monitor stops a run only at its own, looser limits (stop_overlap, its
// energy slack): whatever passes between the two is what this study exists to find.
constexpr double energy_gain_limit = 1e-3;

std::string run_problems(std::int64_t lost, double max_overlap, double max_energy_gain, double overlap_bound) {
  if (lost > 0) return fmt::format("{} grains lost", lost);
  if (max_overlap > overlap_bound)
    return fmt::format("largest overlap {:.3g} of a radius during the run, beyond the bound {:.3g}", max_overlap, overlap_bound);
  if (max_energy_gain > energy_gain_limit)
    return fmt::format("energy grew {:.3g} of Σ m g r beyond what gravity and the walls gave", max_energy_gain);
  return "";
}

std::string settled_result_problems(const dem::State& s, const pipeline::LoopResult& run, double overlap_bound) {
  return run_problems(s.lost, run.max_overlap_rel, run.max_energy_gain, overlap_bound);
}

// The deepest overlap, over the grain's radius, that an elastic head-on impact at `speed` gives
// (docs/PHYSICS.md §6: δ = (15 m* v² / (16 E* √R*))^{2/5}) for the powder's largest grain:
// against an equal grain at rest, 2^{1/5} deeper than against a rigid wall. Damping and impacts
// shared between contacts only lessen it, so a pour whose fastest grain falls at `speed` stays
// below it.
double impact_overlap_bound(const Powder& p, double speed) {
  const double r = p.r_max();
  const double m = p.density * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  const dem::Material& grain = p.spec.materials[std::size_t(p.powder)];
  const double e_star = grain.youngs_modulus / (1 - grain.poisson_ratio * grain.poisson_ratio);
  return std::pow(2.0, 0.2) * std::pow(15 * m * speed * speed / (16 * e_star * std::sqrt(r)), 0.4) / r;
}

double fall_speed(const Powder& p, double height) { return std::sqrt(2 * p.spec.gravity.norm() * height); }

// `count` grains poured into a box of planes (2 half wide) up to `height`; the model with the
// automatic time step and skin tells the probes their limits.
struct BoxBed {
  dem::ModelSpec spec;
  dem::State state;
  dem::Model automatic;
};

BoxBed box_bed(const Powder& powder, double half, double height, std::size_t count) {
  const double d = powder.diameter;
  BoxBed bed;
  bed.spec = powder.spec;
  bed.spec.planes = box_planes(half, powder.wall);
  bed.spec.domain = {Vec3(-half - d, -half - d, -d), Vec3(half + d, half + d, height + 10 * d)};
  dem::InsertRegion region;
  region.box = {Vec3(-half + d, -half + d, d), Vec3(half - d, half - d, height)};
  add_grains(bed.state, region, powder, count, powder.seed);
  bed.automatic = dem::compile_model(bed.spec, bed.state, powder.source);
  return bed;
}

std::string time_step_run(const Powder& powder, double fraction) {
  BoxBed bed = box_bed(powder, 5 * powder.diameter, 20 * powder.diameter, 400);
  dem::ModelSpec& spec = bed.spec;
  dem::State& state = bed.state;
  spec.time_step = fraction * std::min(bed.automatic.dt_rayleigh, bed.automatic.dt_hertz);
  const dem::Model model = dem::compile_model(spec, state, powder.source);
  dem::initialize(model, state);
  const pipeline::LoopResult run = advance(model, state, 0.15, fmt::format("stability: time step {:.3g} of the limit", fraction));
  return settled_result_problems(state, run, impact_overlap_bound(powder, fall_speed(powder, 20 * powder.diameter)));
}

std::string voxel_run(const Powder& powder, double voxel_over_radius, const std::filesystem::path& work) {
  const double r = powder.r_max();
  const std::filesystem::path ring = ring_mesh(work);
  const mesh::DieOptions options = mesh::die_options_for_grains(r, 0.5 * r, voxel_over_radius * r);
  const mesh::PreparedDie die = mesh::prepare_die(ring, options, work / ".cache");
  auto field = std::make_shared<const geometry::WallField>(die.sdf.wall_field(die.solid));
  dem::ModelSpec spec = powder.spec;
  spec.skin = 0.5 * r;  // the default comes from the grains, and the first model has none
  spec.meshes = {dem::fixed_mesh_wall(field, powder.wall, "die")};
  const geometry::Box box = geometry::bounding_box(die.cavity);
  // Wide enough that only a grain through the die leaves it (downwards).
  spec.domain = {box.lo - Vec3(25e-3, 25e-3, 5e-3), box.hi + Vec3(25e-3, 25e-3, 30e-3)};
  spec.max_impact_speed = std::max(spec.max_impact_speed, std::sqrt(2 * spec.gravity.norm() * 25e-3));
  dem::State state;
  const dem::Model empty = dem::compile_model(spec, state, powder.source);
  dem::InsertRegion region;
  region.box = {Vec3(box.lo.x(), box.lo.y(), box.lo.z() + r), Vec3(box.hi.x(), box.hi.y(), box.hi.z() + 15e-3)};
  region.clear_of_walls = &empty;
  // Straight above the annulus, so that every grain falls into the cavity.
  region.accept = [&](const Vec3& x, double radius) {
    const double rho = std::hypot(x.x(), x.y());
    return rho - radius > 5e-3 && rho + radius < 10e-3;
  };
  add_grains(state, region, powder, 600, powder.seed);
  const dem::Model model = dem::compile_model(spec, state, powder.source);
  dem::initialize(model, state);
  const pipeline::LoopResult run = advance(model, state, 0.12, fmt::format("stability: voxel {:.3g} grain radii", voxel_over_radius));
  // Judged by Embree's exact inside test on the die's solid, not by the wall field the contacts
  // used: a wrong sign that let a grain in would also say it is outside.
  const mesh::ExactSurface solid(die.solid);
  std::size_t inside = 0;
  for (std::size_t i = 0; i < state.size(); ++i) inside += state.active[i] && solid.inside(state.x[i]);
  if (inside > 0) return fmt::format("{} grain centres inside the die", inside);
  const double drop = region.box.hi.z() - box.lo.z();  // from the top of the pour to the die's floor
  return settled_result_problems(state, run, impact_overlap_bound(powder, fall_speed(powder, drop)));
}

std::string wall_speed_run(const Powder& powder, double step_over_half_skin) {
  // Slow enough that the push adds little to the dropped bed's own overlaps (4.5-9.9 % of a radius
  // over seeds 1-8): what grows past the bound is the skin's doing. The block stops 7.5 grains
  // short of the far wall: pushed on to 4.5 grains (8 grains of travel), the bed piled above the
  // block against that wall, and the jam reached 0.136 and 0.147 of a radius for some seeds,
  // past the bound without the skin's doing.
  const double d = powder.diameter, r = powder.r_max(), half = 6 * d, speed = 0.1;
  BoxBed bed = box_bed(powder, half, 6 * d, 300);
  dem::ModelSpec& spec = bed.spec;
  dem::State& state = bed.state;
  // A block as wide as the box sweeps the bed; the skin sets the ratio.
  spec.skin = 2 * speed * bed.automatic.dt / step_over_half_skin;
  dem::MeshWall block = block_wall(Vec3(-2 * d, -half, 0), Vec3(0, half, 4 * d), r, powder.wall, "pusher");
  block.motion.start_position = Vec3(-half - 0.5 * d, 0, 0.2 * d);
  block.motion.start_velocity = Vec3(speed, 0, 0);
  spec.meshes = {block};
  const dem::Model model = dem::compile_model(spec, state, powder.source);
  dem::initialize(model, state);
  const pipeline::LoopResult run =
      advance(model, state, 5 * d / speed, fmt::format("stability: wall step {:.3g} of half the skin", step_over_half_skin));
  // A rigid wall pushing a bed: the bound the pipeline's shoe is designed to (half the stop limit).
  return settled_result_problems(state, run, 0.5 * spec.stop_overlap);
}

std::string coarse_cavity_run(const scene::PipelineScene& scene, double diameter_over_width, const std::filesystem::path& work) {
  // The ring's annulus is 5 mm wide.
  scene::PipelineScene s = scene;
  s.powder.coarse_graining = diameter_over_width * 5e-3 / s.powder.particle_diameter;
  s.output.directory = work / fmt::format("cavity_{:.3g}", diameter_over_width);
  const pipeline::DieRun run = pipeline::run_die_fill(s, ring_mesh(work), false);
  const auto& particles = run.report["particles"];
  if (particles.value("in_cavity", 0) == 0) return "no grain entered the cavity";
  const auto& checked = run.report["stability"];
  // The shoe's cut lets a grain it pinches overlap by up to half the stop limit (pipeline.cpp).
  // Grains the shoe spills over the table's edge are physical; those lost are faults.
  return run_problems(particles.value("lost", 0), checked.value("max_overlap_rel", 0.0), checked.value("max_energy_gain", 0.0),
                      0.5 * s.spec.stop_overlap);
}

}  // namespace

void stability(const scene::PipelineScene& scene, bool reduced, Output& out) {
  const Powder powder = powder_of(scene);
  const std::filesystem::path work = out.work();
  const std::vector<double> time_steps = reduced ? std::vector<double>{0.15, 2.0} : std::vector<double>{0.1, 0.2, 0.4, 0.7, 1.0, 1.5, 2.5};
  const std::vector<double> voxels = reduced ? std::vector<double>{0.25, 8.0} : std::vector<double>{0.25, 0.5, 1, 2, 4, 8, 16};
  const std::vector<double> wall_steps = reduced ? std::vector<double>{0.5, 2.0} : std::vector<double>{0.25, 0.5, 0.9, 1.1, 2, 4};
  const std::vector<double> cavity = reduced ? std::vector<double>{0.5, 1.2} : std::vector<double>{0.3, 0.5, 0.8, 1.0, 1.2};

  std::vector<Probe> probes;
  const std::vector<std::string> rows = {"time step / stable limit", "die voxel / grain radius", "wall travel per step / half skin",
                                         "grain diameter / cavity width"};
  for (double f : time_steps) probes.push_back(probe("time_step", rows[0], f, [&] { return time_step_run(powder, f); }));
  for (double f : voxels) probes.push_back(probe("voxel", rows[1], f, [&] { return voxel_run(powder, f, work); }));
  for (double f : wall_steps) probes.push_back(probe("wall_speed", rows[2], f, [&] { return wall_speed_run(powder, f); }));
  for (double f : cavity) probes.push_back(probe("coarse_grains", rows[3], f, [&] { return coarse_cavity_run(scene, f, work); }));

  std::vector<std::vector<nlohmann::json>> table;
  nlohmann::json list = nlohmann::json::array();
  Chart map("stability_map.png", "Where each method fails", "ratio to the method's limit", "");
  map.log_x = true;
  map.y_ticks = rows;
  for (int o = 0; o < 4; ++o) map.series.push_back({outcome_names[o], {}, {}, {}, "points"});
  for (const Probe& p : probes) {
    const auto row = double(std::find(rows.begin(), rows.end(), p.parameter) - rows.begin());
    map.series[std::size_t(p.outcome)].x.push_back(p.ratio);
    map.series[std::size_t(p.outcome)].y.push_back(row);
    // The CSV keeps the message on one line and free of commas.
    std::string detail = p.detail;
    std::replace(detail.begin(), detail.end(), ',', ';');
    std::replace(detail.begin(), detail.end(), '\n', ' ');
    table.push_back({p.name, p.ratio, outcome_names[int(p.outcome)], detail});
    list.push_back({{"probe", p.name}, {"parameter", p.parameter}, {"ratio", p.ratio}, {"outcome", outcome_names[int(p.outcome)]},
                    {"detail", p.detail}});
  }
  out.table("stability.csv", {"probe", "ratio", "outcome", "detail"}, table);
  out.chart(map);
  out.results = {{"grain_diameter_m", powder.diameter}, {"probes", list}};
}

}  // namespace studies
