#include "studies/study_scenes.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/error.hpp"
#include "dem/step.hpp"
#include "mesh/sdf.hpp"
#include "mesh/shapes.hpp"
#include "mesh/tool.hpp"

namespace studies {

using dem::Vec3;

double grain_volume(double diameter) { return std::numbers::pi / 6 * diameter * diameter * diameter; }

double centre_height_quantile(const dem::State& s, double q) {
  std::vector<double> z;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.active[i]) z.push_back(s.x[i].z());
  if (z.empty()) return 0;
  const auto k = std::size_t(q * double(z.size() - 1));
  std::nth_element(z.begin(), z.begin() + std::ptrdiff_t(k), z.end());
  return z[k];
}

namespace {

// Poured loose, the powder settles to a solid fraction of about 0.6 from 0.42.
double pour_height(const SlotContainer& c) { return c.fill_height * 0.6 / 0.42; }

dem::PlaneWall plane(const Vec3& point, const Vec3& normal, int material, const std::string& name) {
  return {point, normal, material, name};
}


// Highest grain top per column (column index from `coordinate`), for the columns in [0, count).
template <class Column>
std::vector<double> column_tops(const dem::State& s, std::size_t count, Column column) {
  std::vector<double> top(count, -std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (!s.active[i]) continue;
    const long c = column(s.x[i]);
    if (c >= 0 && std::size_t(c) < count) top[std::size_t(c)] = std::max(top[std::size_t(c)], s.x[i].z() + s.radius[i]);
  }
  return top;
}

SurfaceFit fit_surface(std::vector<double> position, std::vector<double> height) {
  SurfaceFit fit;
  for (std::size_t i = 0; i < position.size(); ++i)
    if (std::isfinite(height[i])) fit.position.push_back(position[i]), fit.height.push_back(height[i]);
  const LineFit line = fit_line(fit.position, fit.height);
  fit.angle_deg = std::atan(std::abs(line.slope)) * 180 / std::numbers::pi;
  // d(atan s)/ds = 1/(1+s²)
  fit.angle_error_deg = line.slope_error / (1 + line.slope * line.slope) * 180 / std::numbers::pi;
  return fit;
}

}  // namespace

SlotContainer outflow_container(double d, bool reduced) {
  SlotContainer c;
  c.slot_width = 6 * d;
  c.length = c.slot_width + 2 * (reduced ? 10 : 14) * d;
  c.width = (reduced ? 6 : 8) * d;
  c.fill_height = (reduced ? 12 : 16) * d;
  c.flow_time = 1.5;
  c.stop_when_drained = true;
  return c;
}

namespace {

// The container's walls, its floor's two plates beside the slot included, without the gate.
dem::ModelSpec slot_walls(const Powder& p, const SlotContainer& c) {
  const double r = p.r_max(), d = p.diameter;
  const double half_l = 0.5 * c.length, half_w = 0.5 * c.width, floor = 2 * r;
  if (c.slot_width >= c.length - 4 * d)
    throw diefill::InputError(p.source, "slot_width", "leaves no floor beside the slot", "Use a narrower slot");
  dem::ModelSpec spec = p.spec;
  spec.planes = {plane(Vec3(0, -half_w, 0), Vec3::UnitY(), p.wall, "side -y"),
                 plane(Vec3(0, half_w, 0), -Vec3::UnitY(), p.wall, "side +y"),
                 plane(Vec3(-half_l, 0, 0), Vec3::UnitX(), p.wall, "end -x"),
                 plane(Vec3(half_l, 0, 0), -Vec3::UnitX(), p.wall, "end +x")};
  // The floor's plates reach past the side planes so that no grain finds a gap at the corners.
  const double past = 2 * r;
  spec.meshes = {block_wall(Vec3(-half_l - past, -half_w - past, -floor), Vec3(-0.5 * c.slot_width, half_w + past, 0), r,
                            p.wall, "floor -x"),
                 block_wall(Vec3(0.5 * c.slot_width, -half_w - past, -floor), Vec3(half_l + past, half_w + past, 0), r,
                            p.wall, "floor +x")};
  if (c.slot_length > 0 && c.slot_length < c.width) {
    const double half_slot = 0.5 * c.slot_width, half_length = 0.5 * c.slot_length;
    spec.meshes.push_back(block_wall(Vec3(-half_slot, -half_w - past, -floor), Vec3(half_slot, -half_length, 0), r, p.wall, "floor -y"));
    spec.meshes.push_back(block_wall(Vec3(-half_slot, half_length, -floor), Vec3(half_slot, half_w + past, 0), r, p.wall, "floor +y"));
  }
  spec.domain = {Vec3(-half_l - past, -half_w - past, -floor - 4 * d), Vec3(half_l + past, half_w + past, pour_height(c) + 10 * d)};
  spec.max_impact_speed = std::max(spec.max_impact_speed, std::sqrt(2 * spec.gravity.norm() * pour_height(c)));
  return spec;
}

}  // namespace

SlotBed settle_slot_bed(const Powder& p, const SlotContainer& c, const std::string& label) {
  const double r = p.r_max(), d = p.diameter;
  const double half_l = 0.5 * c.length, half_w = 0.5 * c.width;
  dem::ModelSpec gated = slot_walls(p, c);
  gated.planes.push_back(plane(Vec3::Zero(), Vec3::UnitZ(), p.wall, "gate"));
  SlotBed bed;
  const auto wanted = std::size_t(c.length * c.width * c.fill_height * 0.6 / grain_volume(d));
  dem::InsertRegion region;
  region.box = {Vec3(-half_l + r, -half_w + r, r), Vec3(half_l - r, half_w - r, pour_height(c))};
  add_grains(bed.state, region, p, wanted, p.seed);
  const dem::Model shut = dem::compile_model(gated, bed.state, p.source);
  dem::initialize(shut, bed.state);
  advance(shut, bed.state, c.settle_time, label + ": settling");

  // The bed: solid fraction of a slab well inside it, away from the walls and the surface.
  bed.bed_height = centre_height_quantile(bed.state, 0.97);
  const dem::Box3 core{Vec3(-half_l + 2 * d, -half_w + 2 * d, 2 * d), Vec3(half_l - 2 * d, half_w - 2 * d, bed.bed_height - 2 * d)};
  double solid = 0;
  for (std::size_t i = 0; i < bed.state.size(); ++i)
    if (core.contains(bed.state.x[i])) solid += grain_volume(2 * bed.state.radius[i]);
  const Vec3 core_size = core.hi - core.lo;
  if (core_size.minCoeff() <= 0)
    throw diefill::InputError(p.source, "fill_height", "leaves no bed to measure", "Give a container several grains deep");
  bed.bulk_density = p.density * solid / core_size.prod();
  bed.initial_mass = mass_where(bed.state, [&](std::size_t i) { return bed.state.active[i] != 0; });
  return bed;
}

SlotRun drain_bed(const Powder& p, const dem::ModelSpec& open_walls, const SlotContainer& c, SlotBed bed, double gone_below,
                  const std::string& label) {
  SlotRun run;
  static_cast<SlotBed&>(run) = std::move(bed);
  // Open the gate.
  forget_wall_contacts(run.state);
  const dem::Model open = dem::compile_model(open_walls, run.state, p.source);
  dem::initialize(open, run.state);
  const double opened = run.state.time;
  const auto gone = [&](std::size_t i) { return !run.state.active[i] || run.state.x[i].z() < gone_below; };
  double quiet_since = opened;
  pipeline::LoopOptions sampling;
  sampling.outputs.push_back({c.sample_every, [&](const dem::State& s) {
                                const double m = mass_where(s, gone);
                                if (run.discharged.empty() || m > run.discharged.back()) quiet_since = s.time;
                                run.time.push_back(s.time - opened);
                                run.discharged.push_back(m);
                              }});
  sampling.finished = [&](const dem::State& s) {
    return (c.stop_when_drained && s.time - quiet_since > 0.1) ||
           (c.stop_after_steady_flow && run.discharged.back() > steady_flow_until_lost * run.initial_mass);
  };
  advance(open, run.state, opened + c.flow_time, label, sampling);
  return run;
}

SlotRun drain_slot_bed(const Powder& p, const SlotContainer& c, SlotBed bed, const std::string& label) {
  return drain_bed(p, slot_walls(p, c), c, std::move(bed), -2 * p.r_max(), label);
}

SlotRun run_slot_container(const Powder& p, const SlotContainer& c, const std::string& label) {
  return drain_slot_bed(p, c, settle_slot_bed(p, c, label), label);
}

double beverloo_slot(double length, double width, double k, double d) {
  return std::max(0.0, length - k * d) * std::pow(std::max(0.0, width - k * d), 1.5);
}

LineFit steady_rate(const SlotRun& run) {
  std::vector<double> t, m;
  for (std::size_t i = 0; i < run.time.size(); ++i)
    if (run.time[i] >= steady_flow_transient && run.discharged[i] <= steady_flow_until_lost * run.initial_mass)
      t.push_back(run.time[i]), m.push_back(run.discharged[i]);
  return fit_line(t, m);
}

Heap funnel_heap(double d, double pedestal_grains) {
  Heap heap;
  heap.pedestal_radius = pedestal_grains * d;
  // Grains enough for a 45° cone over the pedestal and the dish's layer at a solid fraction of
  // 0.6, so that the heap reaches its angle and sheds over the edge before the pour ends (with
  // just a 35° cone's worth it stayed a flat-topped mound); poured in about a second.
  const double area = std::numbers::pi * heap.pedestal_radius * heap.pedestal_radius;
  heap.grains = std::size_t(0.6 * (area * heap.pedestal_radius / 3 + area * d) / grain_volume(d));
  heap.pour_rate = double(heap.grains);
  heap.drop_height = 2 * d;
  heap.stream_radius = 3 * d;
  return heap;
}

HeapRun run_heap(const Powder& p, const Heap& h, const std::string& label) {
  const double r = p.r_max(), d = p.diameter, base = 4 * d;
  dem::ModelSpec spec = p.spec;
  // Heaps are measured on a base with a layer of grains fixed to it. On a flat plate, however
  // frictional, the bottom layer rolls outward like ball bearings (rolling friction holds a
  // slope of only atan mu_r) and the heap spreads to a few grains' thickness; here the
  // pedestal's top is a dish one grain deep whose first grains, held by its rim, become that
  // layer. The pedestal is powder against powder.
  dem::Material base_material = spec.materials[std::size_t(p.powder)];
  base_material.name = "heap base";
  spec.materials.push_back(base_material);
  const int rough = int(spec.materials.size()) - 1;
  const geometry::TriMesh dish = mesh::ring_cavity(2 * h.pedestal_radius, 0, d, 0.01 * d);
  mesh::TableExtent table = mesh::table_around(dish, 0.25 * d);
  table.thickness = base;
  const mesh::ToolMesh pedestal = mesh::tool_from_cavity(dish, table, "heap pedestal");
  spec.meshes = {dem::fixed_mesh_wall(std::make_shared<const geometry::WallField>(mesh::contact_wall_field(pedestal.mesh, r)), rough, "pedestal")};

  // Batches every 10 ms: a stream of the asked rate, each batch dropped just above the heap.
  const double batch_period = 0.01;
  const auto per_batch = std::max<std::size_t>(1, std::size_t(h.pour_rate * batch_period));
  const double stream_area = std::numbers::pi * h.stream_radius * h.stream_radius;
  const double batch_height = double(per_batch) * grain_volume(d) / (0.3 * stream_area) + 2 * d;
  // The funnel's outlet follows the heap's apex (the highest grain at rest), as an operator
  // raises it, so that grains land softly; the domain holds a heap up to 50°.
  const double top = 1.2 * h.pedestal_radius + h.drop_height + batch_height + 2 * d;
  const double reach = h.pedestal_radius + 10 * d;
  spec.domain = {Vec3(-reach, -reach, -base - 2 * d), Vec3(reach, reach, top)};
  spec.max_impact_speed = std::max(spec.max_impact_speed, std::sqrt(2 * spec.gravity.norm() * top));
  HeapRun run;
  std::optional<dem::Model> model;
  std::size_t poured = 0;
  for (int batch = 0; poured < h.grains; ++batch) {
    double apex = 0;
    for (std::size_t i = 0; i < run.state.size(); ++i)
      if (run.state.active[i] && run.state.v[i].norm() < 0.05) apex = std::max(apex, run.state.x[i].z() + run.state.radius[i]);
    const double floor_z = std::min(apex, 1.2 * h.pedestal_radius) + h.drop_height;
    dem::InsertRegion region;
    region.box = {Vec3(-h.stream_radius, -h.stream_radius, floor_z), Vec3(h.stream_radius, h.stream_radius, floor_z + batch_height)};
    region.accept = [&](const Vec3& x, double radius) {
      return std::hypot(x.x(), x.y()) + radius <= h.stream_radius;
    };
    const std::size_t added = add_grains(run.state, region, p, std::min(per_batch, h.grains - poured), p.seed + std::uint64_t(batch));
    if (added == 0)
      throw diefill::InputError(p.source, "heap.stream_radius", "no grain fits in the stream", "Widen the stream");
    poured += added;
    if (!model) model = dem::compile_model(spec, run.state, p.source);
    dem::initialize(*model, run.state);  // neighbour lists for the new grains
    advance(*model, run.state, run.state.time + batch_period, fmt::format("{}: pouring ({} of {})", label, poured, h.grains));
  }
  advance(*model, run.state, run.state.time + h.settle_time, label + ": settling");
  for (std::size_t i = 0; i < run.state.size(); ++i) run.on_pedestal += run.state.active[i] && run.state.x[i].z() > -d;  // the dish's grains too
  return run;
}

SurfaceFit fit_outflow_surface(const dem::State& s, const SlotContainer& c, double d, int side, double clear) {
  const double from = 0.5 * c.slot_width + clear, to = 0.5 * c.length - clear;
  const auto count = std::size_t(std::max(0.0, std::floor((to - from) / d)));
  const std::vector<double> top = column_tops(s, count, [&](const Vec3& x) {
    if (x.z() < 0 || x.x() * side <= 0) return -1L;
    return long(std::floor((std::abs(x.x()) - from) / d));
  });
  std::vector<double> position(count);
  for (std::size_t k = 0; k < count; ++k) position[k] = from + (double(k) + 0.5) * d;
  return fit_surface(position, top);
}

OutflowAngle outflow_angle(const dem::State& s, const SlotContainer& c, double d, double clear) {
  const SurfaceFit left = fit_outflow_surface(s, c, d, -1, clear), right = fit_outflow_surface(s, c, d, +1, clear);
  // The mean's error: the fits' own, or the two slopes' disagreement where that is larger (the
  // sides of one bed differed by 5.7° with fit errors of 1.3° each: the fit errors alone hid it).
  const double fits = 0.5 * std::hypot(left.angle_error_deg, right.angle_error_deg);
  return {0.5 * (left.angle_deg + right.angle_deg), std::max(fits, 0.5 * std::abs(left.angle_deg - right.angle_deg)),
          left.angle_deg, right.angle_deg};
}

OutflowAngle pooled(const std::vector<OutflowAngle>& beds) {
  std::vector<MeanAndError> angles;
  std::vector<double> left, right;
  for (const OutflowAngle& b : beds) angles.push_back({b.angle_deg, b.error_deg}), left.push_back(b.left_deg), right.push_back(b.right_deg);
  const MeanAndError angle = pooled(angles);
  return {angle.mean, angle.error, mean_and_error(left).mean, mean_and_error(right).mean};
}

SurfaceFit fit_heap_surface(const dem::State& s, const Heap& h, double d) {
  // Square columns one grain wide, each its highest grain top against the radius of its centre,
  // between the apex, flattened under the stream, and the toe. Columns of one area, so that the
  // highest top is as far above the mean surface at every radius (the highest over a ring, or a
  // sector of it, rises with its area, which grows with the radius). The reduced heap's four
  // rings of eight sectors each gave the same powder's beds 18.8-24.9° where their ring profiles
  // stood within a degree of each other; its ~150 columns read the slope of the whole flank.
  const double from = std::max(0.2 * h.pedestal_radius, h.stream_radius + d), to = 0.85 * h.pedestal_radius;
  const long half = long(std::ceil(to / d));
  const long side = 2 * half;
  const auto column_of = [&](const Vec3& x) {
    const long i = long(std::floor(x.x() / d)) + half, j = long(std::floor(x.y() / d)) + half;
    if (x.z() < 0 || i < 0 || j < 0 || i >= side || j >= side) return -1L;
    return j * side + i;
  };
  const std::vector<double> top = column_tops(s, std::size_t(side * side), column_of);
  std::vector<double> position, height;
  for (long j = 0; j < side; ++j)
    for (long i = 0; i < side; ++i) {
      const double radius = std::hypot((double(i - half) + 0.5) * d, (double(j - half) + 0.5) * d);
      if (radius < from || radius > to) continue;
      position.push_back(radius);
      height.push_back(top[std::size_t(j * side + i)]);
    }
  return fit_surface(position, height);
}

}  // namespace studies
