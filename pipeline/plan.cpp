#include "pipeline/plan.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/error.hpp"
#include "core/log.hpp"

namespace pipeline {

using dem::Vec3;

namespace {

// Accelerate to v, cruise, decelerate to rest over `distance` (signed along x).
void add_stroke(dem::Motion& m, double distance, double v, double a) {
  const double sign = distance < 0 ? -1 : 1, d = std::abs(distance);
  double ta = v / a, cruise = d - v * ta;
  if (cruise < 0) ta = std::sqrt(d / a), cruise = 0;  // never reaches v
  m.segments.push_back({ta, Vec3(sign * a, 0, 0)});
  if (cruise > 0) m.segments.push_back({cruise / (a * ta), Vec3::Zero()});  // a ta = v
  m.segments.push_back({ta, Vec3(-sign * a, 0, 0)});
}

// Solid fraction of a settled bed of these spheres (docs/PHYSICS.md §3: poured frictional spheres
// 0.58-0.61): what the shoe's bed holds per volume.
constexpr double bed_solid_fraction = 0.6;

}  // namespace

DieSource read_die(const scene::DieSettings& die_settings, const std::filesystem::path& die_mesh) {
  if (die_settings.role != mesh::WallRole::cavity)
    throw diefill::InputError(die_mesh.string(), "die.role", "the pipeline fills a cavity", "Give the cavity mesh (role \"cavity\")");
  DieSource die;
  die.file = mesh::read_die_file(die_mesh, die_settings.units, die_settings.up, die_settings.parting, die_settings.part);
  if (die.file.up_found && die.file.up != mesh::Up{} && !die.file.parting_z)
    diefill::log::warn("{}: its opening (a flat face at its extreme) faces {} in the file; turned so that it faces up. "
                       "Set die.up to choose another way",
                       die.file.name, mesh::up_name(die.file.up));
  if (die.file.part == 0 && die.file.bodies > 1)
    diefill::log::info("{}: the file holds {} separate bodies (pieces that share no vertex), filled as one part; if they are "
                       "an assembly's parts, die.part = N takes the N-th largest alone (docs/MESHES.md, \"Assemblies\")",
                       die.file.name, die.file.bodies);
  die.box = geometry::bounding_box(die.file.mesh);
  if (die.file.parting_z) {
    // The height of the cut is said once, by the repair action that makes it (mesh/die.cpp), on
    // the repaired part: repair may move the part's lowest point, so a figure here could differ.
    diefill::log::warn("{}: it has no flat face the die could open on{}; the die table cuts it at its widest section "
                       "(its repair actions, logged and in the report, say where), and the upper punch would form the part above. Set "
                       "die.parting = \"opening\" to refuse such a part",
                       die.file.name,
                       die.file.up_found ? fmt::format(" (laid flat: up is {} in the file, the axis of its largest outline)",
                                                       mesh::up_name(die.file.up))
                                         : "");
    die.box.hi.z() = *die.file.parting_z;
  }
  die.table_z = die.box.hi.z();
  return die;
}

ShoePlan plan_shoe(const scene::ShoeSettings& shoe, const scene::MotionSettings& motion, const DieSource& die) {
  ShoePlan p;
  p.length = shoe.length;
  const double die_width = die.box.size().y();
  p.width = shoe.trim_width ? std::min(shoe.width, die_width + 2 * shoe.side_margin) : shoe.width;
  if (p.width < die_width + 2 * shoe.side_margin) {
    diefill::log::warn("the shoe ({:.4g} mm wide) does not cover the die ({:.4g} mm) with its side margin; widened to {:.4g} mm",
                       shoe.width * 1e3, die_width * 1e3, (die_width + 2 * shoe.side_margin) * 1e3);
    p.width = die_width + 2 * shoe.side_margin;
  }
  p.y_centre = 0.5 * (die.box.lo.y() + die.box.hi.y());
  p.x_start = die.box.lo.x() - motion.start_gap - 0.5 * p.length;
  p.x_end = die.box.hi.x() + motion.end_gap + 0.5 * p.length;
  p.motion.start_position = Vec3(p.x_start, p.y_centre, die.table_z);
  for (int pass = 0; pass < motion.passes; ++pass) {
    add_stroke(p.motion, p.x_end - p.x_start, motion.speed, motion.acceleration);
    if (motion.dwell > 0) p.motion.segments.push_back({motion.dwell, Vec3::Zero()});
    if (motion.return_stroke) add_stroke(p.motion, p.x_start - p.x_end, motion.speed, motion.acceleration);
  }
  for (const auto& seg : p.motion.segments) p.t_motion += seg.duration;
  return p;
}

GrainSizing size_grains(const scene::PowderSettings& powder, double fill_height, const ShoePlan& shoe, const std::string& die_name) {
  GrainSizing g;
  g.diameter = powder.grain_diameter();
  const double bed = shoe.length * shoe.width * fill_height * bed_solid_fraction;
  double estimate = bed / (std::numbers::pi / 6 * std::pow(g.diameter, 3));
  if (estimate > double(powder.max_grains)) {
    const double scale = std::cbrt(estimate / double(powder.max_grains));
    diefill::log::warn("{}: {:.0f} grains of {:.3g} mm would exceed powder.max_grains = {}; using {:.3g} mm grains "
                       "(coarse graining {:.3g} instead of {:.3g})",
                       die_name, estimate, g.diameter * 1e3, powder.max_grains, g.diameter * scale * 1e3, powder.coarse_graining * scale,
                       powder.coarse_graining);
    g.diameter *= scale;
    estimate = double(powder.max_grains);
  }
  g.count = std::size_t(estimate);
  g.r_max = 0.5 * g.diameter * (1 + powder.diameter_spread);
  g.alpha = g.diameter / powder.particle_diameter;
  return g;
}

void set_clearance(double clearance, const GrainSizing& grains, double table_z, ShoePlan& shoe) {
  shoe.motion.start_position.z() = table_z + clearance * grains.r_max;
}

FillLayout lay_out_fill(const scene::PipelineScene& s, const std::filesystem::path& die_mesh) {
  FillLayout f{read_die(s.die, die_mesh), {}, {}};
  f.shoe = plan_shoe(s.shoe, s.motion, f.source);
  f.grains = size_grains(s.powder, s.shoe.fill_height, f.shoe, f.source.file.name);
  set_clearance(s.shoe.clearance, f.grains, f.source.table_z, f.shoe);
  return f;
}

}  // namespace pipeline
