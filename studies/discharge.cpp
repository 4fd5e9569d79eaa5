// `diefill study discharge`: the dynamic calibration of the seed study. (a) A container at rest
// drains through a slot: flow rate against slot width, fitted to the Beverloo slot law. (b) The
// pipeline's shoe crosses a die opening at speed v and delivers powder into a deep die (a bin):
// delivered mass against v, against the moving-container law built from (a)'s constants and
// against the critical-velocity law fitted to it (docs/PHYSICS.md §3).
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "pipeline/die_fill.hpp"
#include "studies/studies.hpp"
#include "studies/study_scenes.hpp"
#include "core/log.hpp"
#include "mesh/import.hpp"
#include "mesh/shapes.hpp"

namespace studies {

namespace {

using dem::Vec3;

// The slot form's coefficient, C_s = 1.03 (Myers & Sellers, quoted by Nedderman 1992, ch. 10).
constexpr double published_slot_c = 1.03;

struct DischargeSizes {
  std::vector<double> slot_widths;  // [grain diameters]
  int beds;                         // settled beds (seeds), each drained through every slot
  double container_width, fill_height, flow_time;
  std::vector<double> speeds;       // [m/s]
  double opening, bin_depth, shoe_fill;  // [shoe grain diameters]
  double shoe_coarsening;           // the moving shoe's grains over the slot's
};

// Reduced, the slot keeps its full size and the scene's grains: five widths over a container ten
// grains wide are what pins C_s and k (three widths of a container eight grains wide gave
// C_s = 0.67 ± 0.12, k = 0.81 ± 0.51; the full layout at twice the grain size C_s = 0.92 ± 0.04,
// below the slot law's published range), and it costs about two minutes on one core. The moving
// shoe runs with grains twice as coarse, at six speeds: five above the critical one pin its
// exponent (with three, n = 0.96 ± 0.25). A drain ends when 40 % of the bed is out or at
// flow_time: only the narrowest slot reaches 0.3 s, whose rate 0.2 s (60 samples) still gives to
// about 0.2 %, far inside the 3-5 % scatter between beds that sets the fit's errors.
DischargeSizes discharge_sizes(bool reduced) {
  if (reduced) return {{5, 6.5, 8, 10, 12}, 2, 10, 20, 0.2, {0.15, 0.25, 0.35, 0.5, 0.7, 0.9}, 10, 20, 12, 2};
  return {{5, 6.5, 8, 10, 12}, 2, 10, 20, 0.3, {0.1, 0.2, 0.35, 0.55, 0.8}, 10, 20, 12, 1};
}

// Beverloo slot law W = A (L - k d)(b - k d)^{3/2} with A = C_s rho_b sqrt(g).
struct BeverlooFit {
  double a = 0, k = 0, a_error = 0, k_error = 0;
  double rms_relative_residual = 0;
  double rate(double length, double width, double d) const { return a * beverloo_slot(length, width, k, d); }
};

// With `fixed_a`, only k is fitted: the law with a published coefficient, whose k is then pinned
// far more tightly than when C_s and k, strongly correlated, are both free.
BeverlooFit fit_beverloo(const std::vector<double>& width, const std::vector<double>& rate, double length, double d,
                         std::optional<double> fixed_a = std::nullopt) {
  const std::size_t n = width.size();
  const auto shape = [&](double k, std::size_t i) { return beverloo_slot(length, width[i], k, d); };
  const auto best_a = [&](double k) {
    if (fixed_a) return *fixed_a;
    double fw = 0, ff = 0;
    for (std::size_t i = 0; i < n; ++i) fw += shape(k, i) * rate[i], ff += shape(k, i) * shape(k, i);
    return fw / ff;
  };
  const auto residual = [&](double k) {
    const double a = best_a(k);
    double ssr = 0;
    for (std::size_t i = 0; i < n; ++i) ssr += std::pow(rate[i] - a * shape(k, i), 2);
    return ssr;
  };
  // k on a fine grid (the residual is smooth and cheap); A follows linearly.
  const double k_max = std::min(*std::min_element(width.begin(), width.end()), length) / d - 0.05;
  BeverlooFit fit;
  double best = std::numeric_limits<double>::infinity();
  for (double k = 0; k <= k_max; k += 1e-3)
    if (const double r = residual(k); r < best) best = r, fit.k = k;
  fit.a = best_a(fit.k);
  double rel = 0;
  for (std::size_t i = 0; i < n; ++i) rel += std::pow(rate[i] / (fit.a * shape(fit.k, i)) - 1, 2);
  fit.rms_relative_residual = std::sqrt(rel / double(n));
  const std::size_t parameters = fixed_a ? 1 : 2;
  if (n > parameters) {
    // Standard errors from the linearised model: covariance sigma² (JᵀJ)⁻¹.
    double jaa = 0, jak = 0, jkk = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double ja = shape(fit.k, i);
      const double jk = fit.a * (-d * std::pow(width[i] - fit.k * d, 1.5) -
                                 1.5 * d * (length - fit.k * d) * std::sqrt(width[i] - fit.k * d));
      jaa += ja * ja, jak += ja * jk, jkk += jk * jk;
    }
    const double sigma2 = best / double(n - parameters), det = jaa * jkk - jak * jak;
    fit.a_error = fixed_a ? 0.0 : std::sqrt(sigma2 * jkk / det);
    fit.k_error = fixed_a ? std::sqrt(sigma2 / jkk) : std::sqrt(sigma2 * jaa / det);
  }
  return fit;
}

// docs/PHYSICS.md §3: a shoe of inner length Ls at speed v over an opening Ld x Bd.
double moving_container_mass(const BeverlooFit& f, double d, double shoe_length, double opening_length,
                             double opening_width, double v) {
  const double l = std::min(shoe_length, opening_length) - f.k * d;
  if (l <= 0) return 0;
  return f.a * std::max(0.0, opening_width - f.k * d) / v *
         (0.8 * std::pow(l, 2.5) + std::abs(shoe_length - opening_length) * std::pow(l, 1.5));
}

std::vector<double> sweep(double lo, double hi, int n) {
  std::vector<double> x;
  for (int i = 0; i < n; ++i) x.push_back(lo + (hi - lo) * i / (n - 1));
  return x;
}

// The slot container of (a), for the slot `b_over_d` grains wide.
SlotContainer slot_container(const DischargeSizes& z, double d, double b_over_d) {
  SlotContainer c;
  c.slot_width = b_over_d * d;
  c.length = (z.slot_widths.back() + 2 * 12) * d;
  c.width = z.container_width * d;
  c.fill_height = z.fill_height * d;
  c.flow_time = z.flow_time;
  c.stop_after_steady_flow = true;  // the draining rest, a third of the cost, is not read
  return c;
}

// (a)'s rates, pooled over the beds, per slot width.
struct SlotFlow {
  std::vector<double> widths, rates, errors, densities;
  std::vector<std::vector<nlohmann::json>> rows;
  nlohmann::json bed_rates = nlohmann::json::array();
  Chart histories{"slot_discharge.png", "Discharged mass after the slot opens (first bed)", "time [s]", "discharged mass [g]"};
};

std::vector<SlotBed> settle_beds(const Powder& powder, const DischargeSizes& z) {
  std::vector<SlotBed> beds;
  for (int bed = 0; bed < z.beds; ++bed) {
    Powder seeded = powder;
    seeded.seed += std::uint64_t(bed);
    beds.push_back(settle_slot_bed(seeded, slot_container(z, powder.diameter, z.slot_widths.front()),
                                   fmt::format("discharge: bed {} of {}", bed + 1, z.beds)));
  }
  return beds;
}

// (a) Slot flow: each bed, settled once on the shut gate, drained through every slot width, so
// that the widths' rates share their beds. One bed's rates scatter by 3-5 % from seed to seed
// (two realisations: 23.6 and 23.0 g/s at 5.2 mm, 71.9 and 68.4 g/s at 9.6 mm), as much as the
// slot law's residuals under test: hence the beds, pooled (study_kit.hpp).
SlotFlow measure_slot_flow(const Powder& powder, const DischargeSizes& z) {
  SlotFlow slot;
  const std::vector<SlotBed> beds = settle_beds(powder, z);
  for (double b_over_d : z.slot_widths) {
    const SlotContainer c = slot_container(z, powder.diameter, b_over_d);
    std::vector<MeanAndError> per_bed;
    double density = 0, mass = 0;
    std::size_t samples = 0;
    for (int bed = 0; bed < z.beds; ++bed) {
      const SlotRun run = drain_slot_bed(powder, c, beds[std::size_t(bed)],
                                         fmt::format("discharge: slot {:.3g} mm, bed {} of {}", c.slot_width * 1e3, bed + 1, z.beds));
      const LineFit flow = steady_rate(run);
      if (flow.points < 5)
        diefill::log::warn("discharge: slot {:.3g} mm: only {} samples of steady flow", c.slot_width * 1e3, flow.points);
      per_bed.push_back({flow.slope, flow.slope_error});
      density += run.bulk_density / z.beds, mass += run.initial_mass / z.beds, samples += flow.points;
      if (bed > 0) continue;
      Series h{fmt::format("b = {:.3g} mm", c.slot_width * 1e3), run.time, {}, {}, "line"};
      for (double m : run.discharged) h.y.push_back(m * 1e3);
      slot.histories.series.push_back(h);
    }
    const MeanAndError rate = pooled(per_bed);
    slot.widths.push_back(c.slot_width);
    slot.rates.push_back(rate.mean);
    slot.errors.push_back(rate.error);
    slot.densities.push_back(density);
    nlohmann::json each = nlohmann::json::array();
    for (const MeanAndError& r : per_bed) each.push_back(r.mean);
    slot.bed_rates.push_back(each);
    slot.rows.push_back({c.slot_width, rate.mean, rate.error, density, mass, samples});
  }
  return slot;
}

// (a)'s rates fitted to the Beverloo slot law, C_s free and at its published value.
struct SlotLaw {
  double bulk_density = 0, slot_length = 0;
  BeverlooFit fit, published;
  double c_s = 0, c_s_error = 0;
};

SlotLaw fit_slot_law(const SlotFlow& slot, const DischargeSizes& z, double d, double g) {
  SlotLaw law;
  for (double rho : slot.densities) law.bulk_density += rho / double(slot.densities.size());
  law.slot_length = z.container_width * d;
  law.fit = fit_beverloo(slot.widths, slot.rates, law.slot_length, d);
  const double scale = law.bulk_density * std::sqrt(g);
  law.c_s = law.fit.a / scale, law.c_s_error = law.fit.a_error / scale;
  // The slot law's published coefficient (docs/PHYSICS.md §3): the k it needs, and how well it fits.
  law.published = fit_beverloo(slot.widths, slot.rates, law.slot_length, d, published_slot_c * scale);
  diefill::log::info("discharge: Beverloo slot law C_s = {:.3f} ± {:.3f}, k = {:.2f} ± {:.2f} (bulk density {:.0f} kg/m³); "
                     "with the published C_s = {:.2f}, k = {:.2f} ± {:.2f} (residual {:.1f} %)",
                     law.c_s, law.c_s_error, law.fit.k, law.fit.k_error, law.bulk_density, published_slot_c, law.published.k,
                     law.published.k_error, 100 * law.published.rms_relative_residual);
  return law;
}

void chart_slot_flow(const SlotFlow& slot, const SlotLaw& law, double d, Output& out) {
  Chart flow{"beverloo.png", "Slot discharge against the Beverloo slot law", "slot width b [mm]", "mass flow rate [g/s]"};
  Series measured{"DEM", {}, {}, {}, "points"};
  for (std::size_t i = 0; i < slot.widths.size(); ++i)
    measured.x.push_back(slot.widths[i] * 1e3), measured.y.push_back(slot.rates[i] * 1e3),
        measured.error.push_back(slot.errors[i] * 1e3);
  Series law_curve{fmt::format("Beverloo: C_s = {:.2f}, k = {:.2f}", law.c_s, law.fit.k), {}, {}, {}, "line"};
  for (double b : sweep(law.fit.k * d, slot.widths.back() * 1.1, 60))
    law_curve.x.push_back(b * 1e3), law_curve.y.push_back(law.fit.rate(law.slot_length, b, d) * 1e3);
  flow.series = {measured, law_curve};
  out.chart(flow);
  out.chart(slot.histories);
}

// (b)'s deep die under the moving shoe, whose grains are coarser than the slot's.
struct DeepDie {
  double shoe_d = 0, opening = 0, depth = 0, capacity = 0;
  std::filesystem::path bin;
};

DeepDie deep_die(const DischargeSizes& z, double d, double bulk_density, Output& out) {
  DeepDie die;
  die.shoe_d = z.shoe_coarsening * d;
  die.opening = z.opening * die.shoe_d, die.depth = z.bin_depth * die.shoe_d;
  die.bin = out.work() / "bin.stl";
  std::filesystem::create_directories(out.work());
  mesh::write_stl(
      mesh::box_solid(Vec3(-0.5 * die.opening, -0.5 * die.opening, -die.depth), Vec3(0.5 * die.opening, 0.5 * die.opening, 0)),
      die.bin, geometry::LengthUnit::mm, "diefill discharge study: deep die");
  die.capacity = bulk_density * die.opening * die.opening * die.depth;
  return die;
}

// The law's mass, capped by what the die holds.
double law_mass(const SlotLaw& law, const DeepDie& die, double shoe_length, double v) {
  return std::min(die.capacity, moving_container_mass(law.fit, die.shoe_d, shoe_length, die.opening, die.opening, v));
}

// (b)'s delivered masses, one run of the pipeline per speed.
struct ShoeRuns {
  std::vector<double> law_error;
  std::vector<double> speeds, delivered;
  std::vector<std::vector<nlohmann::json>> rows;
};

ShoeRuns run_moving_shoe(const scene::PipelineScene& scene, const DischargeSizes& z, const SlotLaw& law, const DeepDie& die,
                         Output& out) {
  ShoeRuns shoe;
  for (double v : z.speeds) {
    scene::PipelineScene s = scene;
    s.die.units = geometry::LengthUnit::mm;
    s.motion.speed = v;
    s.motion.acceleration = 10;  // about 1 g: the shoe reaches its speed before the opening
    s.motion.start_gap = v * v / (2 * s.motion.acceleration) + 2e-3;
    s.shoe.fill_height = z.shoe_fill * die.shoe_d;
    s.powder.coarse_graining = scene.powder.coarse_graining * z.shoe_coarsening;
    s.output.directory = out.work() / fmt::format("shoe_{:.3f}_m_s", v);
    const pipeline::DieRun run = pipeline::run_die_fill(s, die.bin, false);
    const double mass = run.report["fill"].value("mass_kg", 0.0);
    shoe.speeds.push_back(v);
    shoe.delivered.push_back(mass);
    shoe.law_error.push_back(mass / law_mass(law, die, scene.shoe.length, v) - 1);
    shoe.rows.push_back({v, mass, mass / die.capacity, law_mass(law, die, scene.shoe.length, v)});
  }
  return shoe;
}

struct CriticalVelocity {
  LineFit power;
  double n = 0, v_c = 0, v_c_error = 0;
  bool falls = true;  // the delivered mass falls with speed above v_c
};

// Critical velocity: delta = (v_c / v)^n where the die is clearly not full.
CriticalVelocity fit_critical_velocity(const ShoeRuns& shoe, double capacity) {
  const std::vector<double>& speeds = shoe.speeds;
  const std::vector<double>& delivered = shoe.delivered;
  std::vector<double> log_v, log_delta;
  for (std::size_t i = 0; i < speeds.size(); ++i)
    if (delivered[i] < 0.9 * capacity && delivered[i] > 0)
      log_v.push_back(std::log(speeds[i])), log_delta.push_back(std::log(delivered[i] / capacity));
  const LineFit power = fit_line(log_v, log_delta);
  const double n = -power.slope, v_c = power.points >= 2 ? std::exp(power.intercept / n) : 0;
  // Error propagation for ln v_c = intercept / n, the two errors taken as independent.
  const double v_c_error = power.points > 2 ? v_c * std::hypot(power.intercept_error / n, power.intercept * power.slope_error / (n * n)) : 0;
  bool falls = true;
  for (std::size_t i = 1; i < speeds.size(); ++i)
    if (speeds[i] > v_c && delivered[i] >= delivered[i - 1]) falls = false;
  return {power, n, v_c, v_c_error, falls};
}

void chart_moving_shoe(const ShoeRuns& shoe, const CriticalVelocity& critical_fit, const SlotLaw& law, const DeepDie& die,
                       double shoe_length, Output& out) {
  const double v_c = critical_fit.v_c, n = critical_fit.n;
  Chart mass_chart{"moving_shoe.png", "Mass a moving shoe delivers into a deep die", "shoe speed [m/s]", "delivered mass [g]"};
  mass_chart.log_x = mass_chart.log_y = true;
  Series dem_points{"DEM", shoe.speeds, {}, {}, "points"};
  for (double m : shoe.delivered) dem_points.y.push_back(m * 1e3);
  Series container_law{"moving-container law (from the slot fit)", {}, {}, {}, "line"};
  Series critical{fmt::format("critical velocity: v_c = {:.3f} m/s, n = {:.2f}", v_c, n), {}, {}, {}, "line"};
  for (double v : sweep(shoe.speeds.front() * 0.8, shoe.speeds.back() * 1.2, 60)) {
    container_law.x.push_back(v);
    container_law.y.push_back(law_mass(law, die, shoe_length, v) * 1e3);
    critical.x.push_back(v);
    critical.y.push_back(die.capacity * (v <= v_c ? 1.0 : std::pow(v_c / v, n)) * 1e3);
  }
  mass_chart.series = {dem_points, container_law, critical};
  out.chart(mass_chart);
}

nlohmann::json slot_results(const SlotFlow& slot, const SlotLaw& law, const DischargeSizes& z) {
  const BeverlooFit& fit = law.fit;
  const BeverlooFit& published = law.published;
  return {{"length_m", law.slot_length},
          {"widths_m", slot.widths},
          {"rates_kg_s", slot.rates},
          {"rate_errors_kg_s", slot.errors},
          {"beds", z.beds},
          {"bed_rates_kg_s", slot.bed_rates},
          {"bulk_density_kg_m3", law.bulk_density},
          {"beverloo", {{"C_s", law.c_s}, {"C_s_error", law.c_s_error}, {"k", fit.k}, {"k_error", fit.k_error},
                        {"rms_relative_residual", fit.rms_relative_residual}}},
          {"beverloo_published_C_s", {{"C_s", published_slot_c}, {"k", published.k}, {"k_error", published.k_error},
                                      {"rms_relative_residual", published.rms_relative_residual}}}};
}

nlohmann::json moving_shoe_results(const ShoeRuns& shoe, const CriticalVelocity& c, const DeepDie& die, double shoe_length) {
  return {{"opening_m", {die.opening, die.opening}},
          {"depth_m", die.depth},
          {"capacity_kg", die.capacity},
          {"shoe_length_m", shoe_length},
          {"speeds_m_s", shoe.speeds},
          {"delivered_kg", shoe.delivered},
          {"moving_container_law_relative_error", shoe.law_error},
          {"critical_velocity", {{"v_c_m_s", c.v_c}, {"v_c_error_m_s", c.v_c_error}, {"n", c.n}, {"n_error", c.power.slope_error},
                                 {"points", c.power.points}}},
          {"delivered_mass_falls_above_v_c", c.falls}};
}

}  // namespace

void discharge(const scene::PipelineScene& scene, bool reduced, Output& out) {
  const Powder powder = powder_of(scene);
  const DischargeSizes z = discharge_sizes(reduced);
  const double d = powder.diameter, g = powder.spec.gravity.norm();

  const SlotFlow slot = measure_slot_flow(powder, z);
  out.table("slot_flow.csv", {"slot_width_m", "rate_kg_s", "rate_error_kg_s", "bulk_density_kg_m3", "bed_mass_kg", "samples"},
            slot.rows);
  const SlotLaw law = fit_slot_law(slot, z, d, g);
  chart_slot_flow(slot, law, d, out);

  // (b) The shoe over a deep die: delivered mass against speed.
  const DeepDie die = deep_die(z, d, law.bulk_density, out);
  const ShoeRuns shoe = run_moving_shoe(scene, z, law, die, out);
  const CriticalVelocity critical = fit_critical_velocity(shoe, die.capacity);
  out.table("moving_shoe.csv", {"speed_m_s", "delivered_kg", "fill_ratio", "moving_container_law_kg"}, shoe.rows);
  chart_moving_shoe(shoe, critical, law, die, scene.shoe.length, out);

  out.results = {{"grain_diameter_m", d},
                 {"shoe_grain_diameter_m", die.shoe_d},
                 {"slot", slot_results(slot, law, z)},
                 {"moving_shoe", moving_shoe_results(shoe, critical, die, scene.shoe.length)}};
}

}  // namespace studies
