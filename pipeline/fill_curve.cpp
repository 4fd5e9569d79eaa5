#include "pipeline/fill_curve.hpp"

#include <fmt/core.h>

#include <cmath>
#include <numbers>

#include "core/atomic_file.hpp"
#include "pipeline/census.hpp"

namespace pipeline {

namespace {

// The part of a sphere of radius r below a plane its centre lies h above (a cap, or all of it).
double volume_below(double r, double h) {
  if (h >= r) return 0;
  if (h <= -r) return 4.0 / 3.0 * std::numbers::pi * r * r * r;
  const double a = r - h;  // the cap's height
  return std::numbers::pi * a * a * (3 * r - a) / 3;
}

}  // namespace

FillSample sample_fill(const dem::State& s, double table_z, double material_density, const ShoePlan& shoe) {
  FillSample out;
  out.time = s.time;
  out.shoe_x = shoe.motion.position(s.time).x();
  double volume = 0;
  for (std::size_t i = 0; i < s.owned(); ++i)
    if (s.active[i] && s.body[i] < 0 && s.x[i].z() < table_z) {
      ++out.grains;
      volume += volume_below(s.radius[i], s.x[i].z() - table_z);
    }
  // A clump's members weighted as the density field bins them (census.hpp).
  const dem::Bodies& b = s.bodies;
  for (std::size_t k = 0; k < b.size(); ++k) {
    if (!b.active[k] || b.x[k].z() >= table_z) continue;
    ++out.grains;
    double below = 0;
    for (std::int32_t m = b.member_start[k]; m < b.member_start[k + 1]; ++m) {
      const std::size_t i = std::size_t(b.member[std::size_t(m)]);
      below += volume_below(s.radius[i], s.x[i].z() - table_z);
    }
    volume += member_weight(s, k) * below;
  }
  if (s.exchange) out.grains = s.exchange->sum(out.grains), volume = s.exchange->sum(volume);
  out.mass = volume * material_density;
  return out;
}

double strike_off_time(const ShoePlan& shoe, double die_far_x) {
  // The first time past it, to a ten-thousandth of the motion, then bisected to the last bit.
  const auto past = [&](double t) { return shoe.motion.position(t).x() - 0.5 * shoe.length >= die_far_x; };
  constexpr int steps = 10000;
  for (int k = 1; k <= steps; ++k) {
    double hi = shoe.t_motion * k / steps;
    if (!past(hi)) continue;
    double lo = shoe.t_motion * (k - 1) / steps;
    for (int n = 0; n < 60; ++n) (past(0.5 * (lo + hi)) ? hi : lo) = 0.5 * (lo + hi);
    return hi;
  }
  return shoe.t_motion;
}

void write_fill_curve(const std::vector<FillSample>& curve, double capacity_kg, const std::filesystem::path& csv,
                      const FillBand* band) {
  const auto share = [&](double mass) { return capacity_kg > 0 ? mass / capacity_kg : 0.0; };
  std::string text = band ? "t_s,shoe_x_m,grains_in_cavity,grains_in_cavity_stderr,mass_in_cavity_kg,mass_in_cavity_kg_stderr,"
                            "fraction_of_capacity,fraction_of_capacity_stderr\n"
                          : "t_s,shoe_x_m,grains_in_cavity,mass_in_cavity_kg,fraction_of_capacity\n";
  for (std::size_t k = 0; k < curve.size(); ++k) {
    const FillSample& p = curve[k];
    text += band ? fmt::format("{:.9g},{:.9g},{:.6g},{:.4g},{:.9g},{:.4g},{:.6g},{:.4g}\n", p.time, p.shoe_x, band->grains[k],
                               band->grains_stderr[k], p.mass, band->mass_stderr[k], share(p.mass), share(band->mass_stderr[k]))
                 : fmt::format("{:.9g},{:.9g},{},{:.9g},{:.6g}\n", p.time, p.shoe_x, p.grains, p.mass, share(p.mass));
  }
  diefill::write_file_atomic(csv, text);
}

}  // namespace pipeline
