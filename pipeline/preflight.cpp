#include "pipeline/preflight.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "core/log.hpp"
#include "dem/state.hpp"

namespace pipeline {

namespace {

// Two grains, the smallest and the largest the size distribution draws: the model's time step is
// the smallest Rayleigh and collision time over its grains, and its skin follows the largest. In
// a domain that just holds them, as a run's holds its grains: the model checks the skin against
// how finely single precision places a grain in its domain (dem/model.cpp), and the default's
// metre would refuse a skin a run's domain takes.
dem::Model compile_on_stand_ins(dem::ModelSpec spec, double diameter, double spread, const std::string& source) {
  const int powder = scene::powder_material(spec);
  dem::State stand_ins;
  const double density = spec.materials[std::size_t(powder)].density;
  stand_ins.add_sphere(0, dem::Vec3::Zero(), 0.5 * diameter * (1 - spread), density, powder);
  stand_ins.add_sphere(1, dem::Vec3(2 * diameter, 0, 0), 0.5 * diameter * (1 + spread), density, powder);
  spec.domain = {dem::Vec3::Constant(-2 * diameter), dem::Vec3::Constant(4 * diameter)};
  return dem::compile_model(spec, stand_ins, source);
}

std::size_t steps_of(double duration, double dt) { return std::size_t(std::llround(duration / dt)); }

}  // namespace

dem::ModelSpec fill_laws(const scene::PipelineScene& s, const GrainSizing& grains, double die_depth) {
  dem::ModelSpec spec = scene::coarse_grained_spec(s.spec, grains.alpha);
  spec.max_impact_speed = std::max(spec.max_impact_speed, std::sqrt(2 * spec.gravity.norm() * die_depth) + s.motion.speed);
  return spec;
}

namespace {

// The grids the outputs bin on, each refused (InputError naming its key) when it would hold more
// voxels than the limit: the density field, the smoothed field, the FEM hand-off's sub-voxels.
void check_grids(const scene::PipelineScene& s, const DieSource& die, const GrainSizing& grains) {
  const double density_voxel = s.density.voxel > 0 ? s.density.voxel : 2 * grains.diameter;
  const double element = s.fem.element_size > 0 ? s.fem.element_size : density_voxel;
  const struct {
    const char* key;
    double voxel;
    const char* remedy;
  } grids[] = {{"density.voxel", density_voxel, "Give a coarser density.voxel"},
               {"density.smoothed_width", s.density.smoothed_width > 0 ? s.density.smoothed_width : 0.5 * grains.diameter,
                "Give a coarser density.smoothed_width"},
               {"fem.element_size", s.fem.elements == scene::FemElements::none ? 0.0 : std::min(0.25 * grains.diameter, 0.125 * element),
                "Give larger elements (fem.element_size; the hand-off's sub-voxels are an eighth of one at most), or set "
                "fem.elements = \"none\""}};
  for (const auto& g : grids) {
    if (g.voxel <= 0) continue;
    const Eigen::Array3d cells = (die.box.size().array() / g.voxel).ceil() + 7;  // a few voxels of margin and kernel
    if (const double voxels = cells.prod(); voxels > voxel_limit)
      throw diefill::InputError(s.source, g.key,
                                fmt::format("voxels of {:.3g} mm over the die ({:.3g} x {:.3g} x {:.3g} mm) make {:.2g} voxels, "
                                            "over the {:.2g} a grid may hold",
                                            g.voxel * 1e3, die.box.size().x() * 1e3, die.box.size().y() * 1e3,
                                            die.box.size().z() * 1e3, voxels, voxel_limit),
                                g.remedy);
  }
}

}  // namespace

RunSize preflight(const scene::PipelineScene& s, const DieSource& die, const ShoePlan& shoe, const GrainSizing& grains) {
  check_grids(s, die, grains);
  RunSize size;
  size.grains = grains.count;
  // The settling sees the scene's impact speed; the pass the raised one and the shoe's motion.
  const dem::Model settling = compile_on_stand_ins(scene::coarse_grained_spec(s.spec, grains.alpha), grains.diameter, s.powder.diameter_spread, s.source);
  const dem::ModelSpec pass_laws = fill_laws(s, grains, die.box.size().z());
  if (pass_laws.max_impact_speed > s.spec.max_impact_speed)
    diefill::log::info("{}: impacts reach {:.3g} m/s in this die; time step set for them (simulation.max_impact_speed is {:.3g})",
                       die.file.name, pass_laws.max_impact_speed, s.spec.max_impact_speed);
  const dem::Model pass = compile_on_stand_ins(pass_laws, grains.diameter, s.powder.diameter_spread, s.source);
  dem::check_wall_travel("shoe", shoe.motion.top_speed(), pass.dt, pass.skin, s.source);
  size.settling_dt_s = settling.dt;
  size.pass_dt_s = pass.dt;
  size.settling_steps = steps_of(s.motion.shoe_settle_time, settling.dt);
  size.pass_steps = steps_of(shoe.t_motion + s.motion.die_settle_time, pass.dt);
  size.particle_steps =
      double(size.grains) * (double(size.pass_steps) + double(max_insertion_rounds) * double(size.settling_steps));
  return size;
}

void preflight_laws(const scene::PipelineScene& s) {
  compile_on_stand_ins(scene::coarse_grained_spec(s.spec, s.powder.coarse_graining), s.powder.grain_diameter(), s.powder.diameter_spread, s.source);
}

void refuse_oversized(const scene::PipelineScene& s, const RunSize& size, const std::string& source) {
  if (size.particle_steps <= particle_step_limit || s.force) return;
  throw diefill::InputError(
      source, "run size",
      fmt::format("the run would take about {:.2g} particle-steps ({} grains, {} steps of {:.3g} s for the pass and up to {} of "
                  "{:.3g} s settling the shoe), over the limit of {:.2g} (10³ times the default ring run's)",
                  size.particle_steps, size.grains, size.pass_steps, size.pass_dt_s,
                  std::size_t(max_insertion_rounds) * size.settling_steps, size.settling_dt_s, particle_step_limit),
      "Coarsen the grains (powder.coarse_graining, powder.max_grains), shorten the motion (motion.speed, motion.passes, "
      "the settle times), or pass --force to run it anyway");
}

std::string describe_size(const RunSize& size, const std::string& die_name) {
  return fmt::format(
      "\n# The run on {}: {} grains. The shoe settles in up to {} rounds of {} steps of {:.3g} s (none when its\n"
      "# settled powder is cached); the pass and the die's settling take {} steps of {:.3g} s. In all about\n"
      "# {:.2g} particle-steps at most (refused over {:.2g}, 10³ times the default ring run's, unless --force).\n",
      die_name, size.grains, max_insertion_rounds, size.settling_steps, size.settling_dt_s, size.pass_steps, size.pass_dt_s,
      size.particle_steps, particle_step_limit);
}

}  // namespace pipeline
