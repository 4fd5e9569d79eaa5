// `diefill study coarse-graining`: does a result change when the grains are coarsened with the
// force laws scaled (docs/PHYSICS.md §4)? Three factors α spanning 4x in grain size (2x reduced),
// each running the same fixed-size experiments: a slot container discharged and drained (flow
// rate, outflow angle) and the bundled ring die filled by the pipeline (fill density). The
// boundary corrections are applied and reported: the Beverloo k·αd term for the flow, and for
// the fill the wall layer, excluded (the core of the cavity) and measured (its thickness).
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "pipeline/die_fill.hpp"
#include "studies/studies.hpp"
#include "studies/study_scenes.hpp"
#include "core/log.hpp"
#include "core/timer.hpp"
#include "dem/io.hpp"
#include "postprocess/density.hpp"

namespace studies {

namespace {

using dem::Vec3;

// k of the Beverloo correction: the middle of the published range for spheres (docs/PHYSICS.md §3).
constexpr double beverloo_k = 1.5;

// Targets of the seed study's invariance claim.
constexpr double target_angle_deg = 2.0, target_flow = 0.05, target_density = 0.02;

// Distance from p into the ring cavity (positive inside): walls, floor and the table.
double into_ring(const Vec3& p) {
  const double r = std::hypot(p.x(), p.y());
  return std::min({r - ring_inner_radius, ring_outer_radius - r, p.z() + ring_depth, -p.z()});
}

// Solid fraction of the points of the ring cavity farther than `margin` from its boundary, from
// the grains' exact volumes on voxels of edge `voxel` (those whose centre lies in that core).
double ring_core_solid_fraction(const dem::State& s, double margin, double voxel) {
  std::vector<post::Grain> grains;
  for (std::size_t i = 0; i < s.size(); ++i) grains.push_back({s.x[i], s.radius[i], 1.0});
  const post::VoxelGrid grid = post::grid_covering(Vec3(-ring_outer_radius, -ring_outer_radius, -ring_depth),
                                                   Vec3(ring_outer_radius, ring_outer_radius, 0), voxel,
                                                   Vec3(voxel / 2, voxel / 2, 0));
  std::vector<double> solid;
  post::bin_exact(grains, grid, solid);
  double core_solid = 0, core_volume = 0;
  for (int i = 0; i < grid.nx; ++i)
    for (int j = 0; j < grid.ny; ++j)
      for (int k = 0; k < grid.nz; ++k)
        if (into_ring(grid.centre(i, j, k)) > margin)
          core_solid += solid[grid.index(i, j, k)], core_volume += grid.voxel_volume();
  return core_solid / core_volume;
}

// The fixed geometry, in units of the coarsest grain D.
struct CoarseGrainingSizes {
  std::vector<double> relative_sizes;  // of the grains, against the scene's
  double slot, beside_slot, width, fill_height;
  std::vector<int> beds;  // drained per size (seeds), their results pooled
};

CoarseGrainingSizes coarse_graining_sizes(bool reduced) {
  // Reduced: without the default's finest, most costly grains, in a container that holds the
  // coarsest eight across its slot and ten across its width, with beds enough that no size's
  // mean is much noisier than another's (4, 6 and 16; the coarse beds are the cheap ones).
  // Measured over draws of the seed (docs/STUDIES.md, "coarse-graining"): seven across and two
  // beds a size, the coarsest's mean outflow angle scattered by 1.3° and its flow rate by 6.3 %
  // from draw to draw, and the 2° and 5 % checks held for four draws of ten; with 2, 6 and 16
  // beds the coarsest's scatter fell to 0.1° and 0.6 %, showing what it had hidden: the sizes'
  // rates 5.3 % (3.2-6.9 %) from one Beverloo law, so that the check failed for four draws of
  // six. Ten across (the slot runs from side wall to side wall) the rates were one law within
  // 1.6-4.4 % and the angles 0.98-1.84° apart over six draws, the finest grains' two beds now the
  // noisiest (0.32° from draw to draw, the others' 0.26° and 0.11°): hence four.
  if (reduced) return {{1, std::sqrt(2.0), 2}, 8, 10, 10, 8, {4, 6, 16}};
  return {{0.5, 1, 2}, 6, 10, 5, 8, {1, 1, 1}};
}

// Held equal for every factor, so that the finest grains stay affordable: a tenth of the
// powder's stiffness and twice the default time-step fraction (the speed-accuracy study
// measures what each costs in accuracy).
scene::PipelineScene affordable(scene::PipelineScene s) {
  s.spec.materials[std::size_t(scene::powder_material(s.spec))].youngs_modulus *= 0.1;
  s.spec.time_step_fraction = 0.3;
  return s;
}

struct FactorResult {
  double alpha = 0, diameter = 0;
  double rate = 0, rate_error = 0, corrected_rate = 0, bulk_density = 0;
  int beds = 0;
  std::size_t slot_grains = 0;
  OutflowAngle outflow;
  double fill_ratio = 0, core_fraction = 0, wall_layer = 0;  // wall_layer: thickness [m]
  std::size_t cavity_grains = 0;
  double seconds = 0;
};

// max |x / mean - 1|.
double spread(const std::vector<double>& x) {
  double mean = 0;
  for (double v : x) mean += v / double(x.size());
  double worst = 0;
  for (double v : x) worst = std::max(worst, std::abs(v / mean - 1));
  return worst;
}

// The k for which the Beverloo slot law makes the rates of all factors one constant (least
// squares in the logarithms), on a 0.01 grid.
double beverloo_k_across(const std::vector<double>& rates, const std::vector<double>& diameters, double length, double width) {
  double best_k = 0, best = std::numeric_limits<double>::infinity();
  const double coarsest = *std::max_element(diameters.begin(), diameters.end());
  for (double k = 0; k * coarsest < 0.9 * std::min(length, width); k += 0.01) {
    std::vector<double> log_a;
    for (std::size_t i = 0; i < rates.size(); ++i) log_a.push_back(std::log(rates[i] / beverloo_slot(length, width, k, diameters[i])));
    double mean = 0, ssr = 0;
    for (double v : log_a) mean += v / double(log_a.size());
    for (double v : log_a) ssr += (v - mean) * (v - mean);
    if (ssr < best) best = ssr, best_k = k;
  }
  return best_k;
}

// The slot container, the same for every factor.
SlotContainer slot_box(const CoarseGrainingSizes& z, double coarsest) {
  SlotContainer box;
  box.slot_width = z.slot * coarsest;
  box.length = box.slot_width + 2 * z.beside_slot * coarsest;
  box.width = z.width * coarsest;
  box.fill_height = z.fill_height * coarsest;
  box.flow_time = 1.5;
  box.stop_when_drained = true;
  return box;
}

// The ring's cavity: volume and the surface the fill touches (walls, floor and the struck-off top).
struct RingCavity {
  double volume = 0, surface = 0;
};

RingCavity ring_cavity() {
  const double ring_area = std::numbers::pi * (ring_outer_radius * ring_outer_radius - ring_inner_radius * ring_inner_radius);
  const double ring_volume = ring_area * ring_depth;
  const double ring_surface = 2 * ring_area + 2 * std::numbers::pi * (ring_outer_radius + ring_inner_radius) * ring_depth;
  return {ring_volume, ring_surface};
}

// What one factor's experiments share.
struct FactorSetup {
  CoarseGrainingSizes z;
  SlotContainer box;
  double coarsest = 0;
  RingCavity ring;
  bool fill_ring = false;
};

// The factor's beds drained through the slot: flow rate, outflow angle and bulk density, pooled.
void drain_beds(FactorResult& f, const Powder& powder, int beds, const FactorSetup& setup, const std::string& label) {
  std::vector<MeanAndError> bed_rates;
  std::vector<OutflowAngle> bed_angles;
  f.beds = beds;
  for (int bed = 0; bed < beds; ++bed) {
    Powder seeded = powder;
    seeded.seed += std::uint64_t(bed);
    const SlotRun slot = run_slot_container(seeded, setup.box, fmt::format("{}, slot (bed {} of {})", label, bed + 1, beds));
    const LineFit flow = steady_rate(slot);
    bed_rates.push_back({flow.slope, flow.slope_error});
    f.bulk_density += slot.bulk_density / beds;
    f.slot_grains = slot.state.size();
    // The same columns for every factor: clear of the slot and the end wall by the coarsest grain.
    bed_angles.push_back(outflow_angle(slot.state, setup.box, f.diameter, setup.coarsest));
  }
  const MeanAndError rate = pooled(bed_rates);
  f.rate = rate.mean, f.rate_error = rate.error;
  f.outflow = pooled(bed_angles);
}

// The ring die filled by the pipeline at the factor's grain size: fill ratio, core fraction and wall layer.
void fill_ring_die(FactorResult& f, scene::PipelineScene s, const Powder& powder, const scene::PipelineScene& scene,
                   const FactorSetup& setup, Output& out) {
  s.output.directory = out.work() / fmt::format("ring_alpha_{:.3g}", f.alpha);
  s.shoe.fill_height = 5e-3;  // twice what the ring takes
  s.shoe.side_margin = 2e-3;
  const pipeline::DieRun ring = pipeline::run_die_fill(s, ring_mesh(out.work()), false);
  const dem::State fill = dem::read_particles(ring.dir / "particles.csv", 0, powder.density);
  f.fill_ratio = ring.report["fill"].value("fill_ratio", 0.0);
  f.cavity_grains = ring.report["particles"].value("in_cavity", std::size_t(0));
  f.core_fraction = ring_core_solid_fraction(fill, setup.coarsest, 0.25 * scene.powder.grain_diameter() * setup.z.relative_sizes.front());
  // A layer of thickness t empty and the rest at the core's fraction gives the mean fill.
  f.wall_layer = setup.ring.volume / setup.ring.surface * (1 - f.fill_ratio / f.core_fraction);
}

FactorResult run_factor(const scene::PipelineScene& scene, double relative, int beds, const FactorSetup& setup, Output& out) {
  diefill::Stopwatch clock;
  FactorResult f;
  scene::PipelineScene s = scene;
  s.powder.coarse_graining = scene.powder.coarse_graining * relative;
  f.alpha = s.powder.coarse_graining;
  f.diameter = s.powder.grain_diameter();
  const Powder powder = powder_of(s);
  const std::string label = fmt::format("coarse-graining: α = {:.3g} ({:.3g} mm)", f.alpha, f.diameter * 1e3);

  drain_beds(f, powder, beds, setup, label);
  const SlotContainer& box = setup.box;
  // The rate the real powder would give by the Beverloo law, from this one's.
  f.corrected_rate = f.rate * beverloo_slot(box.width, box.slot_width, beverloo_k, s.powder.particle_diameter) /
                     beverloo_slot(box.width, box.slot_width, beverloo_k, f.diameter);

  if (setup.fill_ring) fill_ring_die(f, s, powder, scene, setup, out);
  f.seconds = clock.seconds();
  diefill::log::info("{}: flow {:.2f} g/s (real-powder Beverloo {:.2f}), outflow {:.1f}° ± {:.1f}°{}; {:.0f} s", label, f.rate * 1e3,
                     f.corrected_rate * 1e3, f.outflow.angle_deg, f.outflow.error_deg,
                     setup.fill_ring ? fmt::format(", ring fill {:.3f}, core {:.3f}, wall layer {:.2f} d", f.fill_ratio, f.core_fraction,
                                                   f.wall_layer / f.diameter)
                                     : "",
                     f.seconds);
  return f;
}

// The factors' results side by side, and how far they agree.
struct Comparison {
  std::vector<double> rates, corrected, angles, fills, cores, layers, diameters;
  double k_across = 0;
  std::vector<double> corrected_fitted;
  double angle_range = 0;
  double layer = 0, core = 0;
  double real_fill = 0;
};

Comparison compare_factors(const std::vector<FactorResult>& results, const SlotContainer& box, const RingCavity& ring,
                           double particle_diameter) {
  Comparison c;
  for (const FactorResult& f : results) {
    c.diameters.push_back(f.diameter);
    c.rates.push_back(f.rate), c.corrected.push_back(f.corrected_rate), c.angles.push_back(f.outflow.angle_deg);
    c.fills.push_back(f.fill_ratio), c.cores.push_back(f.core_fraction), c.layers.push_back(f.wall_layer / f.diameter);
  }
  c.k_across = beverloo_k_across(c.rates, c.diameters, box.width, box.slot_width);
  for (const FactorResult& f : results)
    c.corrected_fitted.push_back(f.rate / beverloo_slot(box.width, box.slot_width, c.k_across, f.diameter));
  const auto [lowest, highest] = std::minmax_element(c.angles.begin(), c.angles.end());
  c.angle_range = *highest - *lowest;
  for (std::size_t i = 0; i < results.size(); ++i)
    c.layer += c.layers[i] / double(c.layers.size()), c.core += c.cores[i] / double(c.cores.size());
  // The real powder's fill by the wall-layer model: the core's fraction, less a layer as thick,
  // in its own diameters, as the coarse grains' layers.
  c.real_fill = c.core * (1 - ring.surface * c.layer * particle_diameter / ring.volume);
  return c;
}

void write_factors_table(const std::vector<FactorResult>& results, bool fill_ring, Output& out) {
  std::vector<std::vector<nlohmann::json>> rows;
  const auto ring_cell = [&](nlohmann::json value) { return fill_ring ? value : nlohmann::json(""); };
  for (const FactorResult& f : results)
    rows.push_back({f.alpha, f.diameter, f.beds, f.slot_grains, f.rate, f.rate_error, f.corrected_rate, f.bulk_density, f.outflow.angle_deg,
                    f.outflow.error_deg, ring_cell(f.cavity_grains), ring_cell(f.fill_ratio), ring_cell(f.core_fraction),
                    ring_cell(f.wall_layer), f.seconds});
  out.table("coarse_graining.csv",
            {"alpha", "grain_diameter_m", "slot_beds", "slot_grains", "rate_kg_s", "rate_error_kg_s", "beverloo_corrected_rate_kg_s",
             "bulk_density_kg_m3", "outflow_angle_deg", "outflow_error_deg", "ring_grains_in_cavity", "ring_fill_ratio",
             "ring_core_solid_fraction", "ring_wall_layer_m", "wall_s"},
            rows);
}

Series relative_series(const std::vector<FactorResult>& results, const std::string& label, const std::vector<double>& y) {
  Series series{label, {}, {}, {}, "points"};
  for (std::size_t i = 0; i < results.size(); ++i)
    series.x.push_back(results[i].diameter * 1e3), series.y.push_back(100 * (y[i] / y.front() - 1));
  return series;
}

void chart_invariance(const std::vector<FactorResult>& results, const Comparison& c, bool fill_ring, Output& out) {
  Chart invariance{"coarse_graining.png", "Results against grain size, relative to the finest grains", "grain diameter [mm]",
                   "change from the finest [%]"};
  invariance.series = {relative_series(results, "flow rate", c.rates),
                       relative_series(results, "flow rate, Beverloo k·αd corrected (k = 1.5)", c.corrected),
                       relative_series(results, fmt::format("flow rate, corrected with the fitted k = {:.2f}", c.k_across),
                                       c.corrected_fitted)};
  if (fill_ring)
    invariance.series.insert(invariance.series.end(), {relative_series(results, "ring fill, whole cavity", c.fills),
                                                       relative_series(results, "ring fill, core (wall layer excluded)", c.cores)});
  out.chart(invariance);
}

void chart_outflow_angles(const std::vector<FactorResult>& results, Output& out) {
  Chart angle_chart{"coarse_graining_repose.png", "Outflow angle of repose against grain size", "grain diameter [mm]", "angle [°]"};
  Series angle_series{"outflow angle (DEM)", {}, {}, {}, "points"};
  for (const FactorResult& f : results)
    angle_series.x.push_back(f.diameter * 1e3), angle_series.y.push_back(f.outflow.angle_deg), angle_series.error.push_back(f.outflow.error_deg);
  angle_chart.series = {angle_series};
  out.chart(angle_chart);
}

nlohmann::json factors_json(const std::vector<FactorResult>& results, bool fill_ring) {
  nlohmann::json factors = nlohmann::json::array();
  for (const FactorResult& f : results) {
    nlohmann::json factor = {{"alpha", f.alpha},
                             {"grain_diameter_m", f.diameter},
                             {"slot", {{"beds", f.beds}, {"grains", f.slot_grains}, {"rate_kg_s", f.rate}, {"rate_error_kg_s", f.rate_error},
                                       {"beverloo_corrected_rate_kg_s", f.corrected_rate}, {"bulk_density_kg_m3", f.bulk_density},
                                       {"outflow_angle_deg", f.outflow.angle_deg}, {"outflow_angle_error_deg", f.outflow.error_deg}}},
                             {"wall_s", f.seconds}};
    if (fill_ring)
      factor["ring"] = {{"grains_in_cavity", f.cavity_grains}, {"fill_ratio", f.fill_ratio}, {"core_solid_fraction", f.core_fraction},
                        {"wall_layer_m", f.wall_layer}, {"wall_layer_over_d", f.wall_layer / f.diameter}};
    factors.push_back(factor);
  }
  return factors;
}

nlohmann::json target(double measured, double goal) {
  return nlohmann::json{{"measured", measured}, {"target", goal}, {"met", measured <= goal}};
}

nlohmann::json coarse_graining_results(const std::vector<FactorResult>& results, const Comparison& c, const scene::PipelineScene& scene,
                                       const FactorSetup& setup) {
  const SlotContainer& box = setup.box;
  nlohmann::json r = {
      {"factors", factors_json(results, setup.fill_ring)},
      {"settings", {{"powder_youngs_modulus_pa", scene.spec.materials[std::size_t(scene::powder_material(scene.spec))].youngs_modulus},
                    {"time_step_fraction", scene.spec.time_step_fraction},
                    {"beverloo_k", beverloo_k},
                    {"beverloo_k_that_makes_the_rates_one_law", c.k_across},
                    {"slot", {{"width_m", box.slot_width}, {"length_m", box.width}, {"box_length_m", box.length},
                              {"fill_height_m", box.fill_height}}},
                    {"ring_core_margin_m", setup.coarsest}}},
      {"invariance",
       {{"outflow_angle_range_deg", target(c.angle_range, target_angle_deg)},
        {"flow_rate_spread", target(spread(c.rates), target_flow)},
        {"flow_rate_spread_beverloo_corrected", target(spread(c.corrected), target_flow)},
        {"flow_rate_spread_beverloo_fitted_k", target(spread(c.corrected_fitted), target_flow)}}}};
  if (setup.fill_ring) {
    r["invariance"]["fill_density_spread"] = target(spread(c.fills), target_density);
    r["invariance"]["fill_density_spread_core"] = target(spread(c.cores), target_density);
    r["wall_layer_over_d_mean"] = c.layer;
    r["real_powder_fill_ratio_predicted"] = c.real_fill;
  }
  return r;
}

}  // namespace

void coarse_graining(const scene::PipelineScene& scene_in, bool reduced, Output& out) {
  const CoarseGrainingSizes z = coarse_graining_sizes(reduced);
  const scene::PipelineScene scene = affordable(scene_in);
  const double coarsest = scene.powder.grain_diameter() * z.relative_sizes.back();
  // Reduced, the ring is not filled: 0.8-1.6 mm grains are 3 to 6 across its annulus, far from
  // the 20 that docs/PHYSICS.md §4 asks for, so their fill tests no invariance (the pipeline tests
  // fill it); the slot container scales with the grains and is the whole reduced study.
  const FactorSetup setup{z, slot_box(z, coarsest), coarsest, ring_cavity(), !reduced};

  std::vector<FactorResult> results;
  for (std::size_t k = 0; k < z.relative_sizes.size(); ++k) results.push_back(run_factor(scene, z.relative_sizes[k], z.beds[k], setup, out));
  const Comparison comparison = compare_factors(results, setup.box, setup.ring, scene.powder.particle_diameter);

  write_factors_table(results, setup.fill_ring, out);
  chart_invariance(results, comparison, setup.fill_ring, out);
  chart_outflow_angles(results, out);
  out.results = coarse_graining_results(results, comparison, scene, setup);
}

}  // namespace studies
