// `diefill study repose`: the static calibration of the seed study. The heap angle (grains rained
// onto a round pedestal) and the outflow angle (what stays in a container drained through a
// slot), each from a straight-line fit of the free surface with its standard error, against
// the grains' sliding and rolling friction, beside the correlation of Zhou et al. (2002).
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "studies/studies.hpp"
#include "studies/study_scenes.hpp"
#include "core/log.hpp"
#include "dem/io.hpp"

namespace studies {

namespace {

struct Friction {
  double sliding, rolling;
};

// docs/PHYSICS.md §3, Zhou et al. 2002: degrees; d and the rolling arms (μ_r R*) in mm.
double zhou_angle(double mu_pp, double mu_pw, double arm_pp_mm, double arm_pw_mm, double d_mm) {
  return 68.61 * std::pow(mu_pp, 0.27) * std::pow(mu_pw, 0.22) * std::pow(arm_pp_mm, 0.06) * std::pow(arm_pw_mm, 0.12) *
         std::pow(d_mm, -0.2);
}

// Sliding friction swept at the scene's rolling friction, and rolling at its sliding. Reduced,
// one step each way, wide enough to show above the small beds' scatter (from 0.25 the outflow
// angle rose 1.5° with errors of 2°: docs/STUDIES.md).
std::vector<Friction> friction_cases(const dem::Material& grain, bool reduced) {
  const std::vector<double> sliding = reduced ? std::vector<double>{0.1} : std::vector<double>{0.2, 0.35, 0.5, 0.7, 0.9};
  const std::vector<double> rolling = reduced ? std::vector<double>{0.0} : std::vector<double>{0.0, 0.05, 0.2, 0.4};
  std::vector<Friction> cases;
  for (double mu : sliding) cases.push_back({mu, grain.rolling_friction});
  for (double mu_r : rolling) cases.push_back({grain.sliding_friction, mu_r});
  if (reduced) cases.push_back({grain.sliding_friction, grain.rolling_friction});
  return cases;
}

// Beds of other seeds per friction, pooled (study_kit.hpp): one reduced bed's angles move by
// about 2° (heap) and 3° (outflow) from seed to seed (standard deviations over seven seeds), more
// than their fits' errors say. The heap's rise with rolling friction, about 4.5°, needs six beds
// to stand more than two combined errors clear of that scatter; its rise with sliding friction
// (about 11° from μ = 0.1) and the outflow's (about 8°), three. The default size pours one bed
// per friction.
int outflow_beds_for(bool reduced) { return reduced ? 3 : 1; }
int heap_beds_for(const Friction& f, const dem::Material& grain, bool reduced) {
  if (!reduced) return 1;
  return f.sliding < grain.sliding_friction ? 3 : 6;
}

Powder with_friction(const Powder& base, const Friction& f) {
  Powder p = base;
  p.spec.materials[std::size_t(p.powder)].sliding_friction = f.sliding;
  p.spec.materials[std::size_t(p.powder)].rolling_friction = f.rolling;
  return p;
}

// One friction's beds: each heap's fitted angle and each drained container's outflow angle.
struct Beds {
  std::vector<MeanAndError> heaps;
  std::vector<OutflowAngle> outflows;
  std::size_t on_pedestal = 0;
};

Beds pour_and_drain(const Powder& p, const Friction& f, const Heap& heap, const SlotContainer& drain, int heap_beds, int outflow_beds,
                    const std::string& label, Output& out) {
  const double d = p.diameter;
  Beds beds;
  std::filesystem::create_directories(out.work());
  for (int bed = 0; bed < std::max(heap_beds, outflow_beds); ++bed) {
    Powder seeded = p;
    seeded.seed += std::uint64_t(bed);
    const std::string bed_label = fmt::format("{} (bed {})", label, bed + 1);
    // The final beds, for a look in ParaView.
    const std::string tag = fmt::format("mu{:.2f}_mur{:.2f}_bed{}", f.sliding, f.rolling, bed + 1);
    if (bed < heap_beds) {
      const HeapRun h = run_heap(seeded, heap, bed_label + ", heap");
      const SurfaceFit heap_fit = fit_heap_surface(h.state, heap, d);
      dem::write_vtu(h.state, out.work() / ("heap_" + tag + ".vtu"));
      beds.heaps.push_back({heap_fit.angle_deg, heap_fit.angle_error_deg});
      beds.on_pedestal += h.on_pedestal;
    }
    if (bed < outflow_beds) {
      const SlotRun o = run_slot_container(seeded, drain, bed_label + ", outflow");
      dem::write_vtu(o.state, out.work() / ("outflow_" + tag + ".vtu"));
      beds.outflows.push_back(outflow_angle(o.state, drain, d, 2 * d));
    }
  }
  return beds;
}

// Pools one friction's beds, reports them beside Zhou's angle and adds them to the table's rows
// and the results' runs.
void record_friction(const Friction& f, const std::string& label, const Beds& beds, int heap_beds, double d,
                     std::vector<std::vector<nlohmann::json>>& rows, nlohmann::json& runs) {
  const MeanAndError heap_angle = pooled(beds.heaps);
  const OutflowAngle outflow = pooled(beds.outflows);
  // The heap's base is coated with the powder (study_scenes.hpp): its friction is the grains'.
  const double zhou = zhou_angle(f.sliding, f.sliding, f.rolling * 0.25 * d * 1e3, f.rolling * 0.5 * d * 1e3, d * 1e3);
  diefill::log::info("{}: heap {:.1f}° ± {:.1f}°, outflow {:.1f}° ± {:.1f}°, Zhou {:.1f}°", label, heap_angle.mean,
                     heap_angle.error, outflow.angle_deg, outflow.error_deg, zhou);
  rows.push_back({f.sliding, f.rolling, heap_angle.mean, heap_angle.error, outflow.angle_deg, outflow.error_deg,
                  std::isfinite(zhou) ? nlohmann::json(zhou) : nlohmann::json("")});
  std::vector<double> heap_bed_angles, outflow_bed_angles;
  for (const MeanAndError& b : beds.heaps) heap_bed_angles.push_back(b.mean);
  for (const OutflowAngle& b : beds.outflows) outflow_bed_angles.push_back(b.angle_deg);
  runs.push_back({{"sliding_friction", f.sliding},
                  {"rolling_friction", f.rolling},
                  {"heap_angle_deg", heap_angle.mean},
                  {"heap_angle_error_deg", heap_angle.error},
                  {"heap_grains", beds.on_pedestal / std::size_t(heap_beds)},
                  {"outflow_angle_deg", outflow.angle_deg},
                  {"outflow_angle_error_deg", outflow.error_deg},
                  {"outflow_sides_deg", {outflow.left_deg, outflow.right_deg}},
                  {"heap_bed_angles_deg", heap_bed_angles},
                  {"outflow_bed_angles_deg", outflow_bed_angles},
                  {"zhou_angle_deg", zhou}});
}

// One chart per swept friction, the other held at the scene's value.
void chart_repose(const nlohmann::json& runs, const dem::Material& grain, bool rolling_axis, Output& out) {
  Chart c{rolling_axis ? "repose_rolling.png" : "repose_sliding.png",
          rolling_axis ? fmt::format("Angle of repose against rolling friction (μ = {:.2f})", grain.sliding_friction)
                       : fmt::format("Angle of repose against sliding friction (μ_r = {:.2f})", grain.rolling_friction),
          rolling_axis ? "rolling friction μ_r" : "sliding friction μ", "angle [°]"};
  Series heap_series{"heap (DEM)", {}, {}, {}, "points"}, outflow_series{"outflow (DEM)", {}, {}, {}, "points"},
      zhou_series{"Zhou et al. 2002", {}, {}, {}, "line"};
  for (const auto& r : runs) {
    const double held = rolling_axis ? r["sliding_friction"].get<double>() : r["rolling_friction"].get<double>();
    if (held != (rolling_axis ? grain.sliding_friction : grain.rolling_friction)) continue;
    const double x = rolling_axis ? r["rolling_friction"].get<double>() : r["sliding_friction"].get<double>();
    heap_series.x.push_back(x), heap_series.y.push_back(r["heap_angle_deg"]), heap_series.error.push_back(r["heap_angle_error_deg"]);
    outflow_series.x.push_back(x), outflow_series.y.push_back(r["outflow_angle_deg"]),
        outflow_series.error.push_back(r["outflow_angle_error_deg"]);
    if (const double z = r["zhou_angle_deg"].get<double>(); std::isfinite(z) && z > 0) zhou_series.x.push_back(x), zhou_series.y.push_back(z);
  }
  c.series = {heap_series, outflow_series, zhou_series};
  out.chart(c);
}

}  // namespace

void repose(const scene::PipelineScene& scene, bool reduced, Output& out) {
  const Powder base = powder_of(scene);
  const double d = base.diameter;
  const dem::Material& grain = base.spec.materials[std::size_t(base.powder)];
  const std::vector<Friction> cases = friction_cases(grain, reduced);

  const Heap heap = funnel_heap(d, reduced ? 10 : 15);
  const SlotContainer drain = outflow_container(d, reduced);

  const int outflow_beds = outflow_beds_for(reduced);
  std::vector<std::vector<nlohmann::json>> rows;
  nlohmann::json runs = nlohmann::json::array();
  for (const Friction& f : cases) {
    const int heap_beds = heap_beds_for(f, grain, reduced);
    const Powder p = with_friction(base, f);
    const std::string label = fmt::format("repose: μ = {:.2f}, μ_r = {:.2f}", f.sliding, f.rolling);
    const Beds beds = pour_and_drain(p, f, heap, drain, heap_beds, outflow_beds, label, out);
    record_friction(f, label, beds, heap_beds, d, rows, runs);
  }
  out.table("repose.csv",
            {"sliding_friction", "rolling_friction", "heap_angle_deg", "heap_error_deg", "outflow_angle_deg", "outflow_error_deg",
             "zhou_angle_deg"},
            rows);

  chart_repose(runs, grain, false, out);
  chart_repose(runs, grain, true, out);
  out.results = {{"grain_diameter_m", d},
                 {"heap", {{"pedestal_radius_m", heap.pedestal_radius}, {"grains_poured", heap.grains}}},
                 {"outflow", {{"slot_width_m", drain.slot_width}, {"length_m", drain.length}, {"width_m", drain.width}}},
                 {"runs", runs}};
}

}  // namespace studies
