#include "studies/measured_powder.hpp"

#include <fmt/core.h>

#include "core/error.hpp"
#include "scene/toml_reader.hpp"

namespace studies {

namespace {

// A number that must lie in [lo, hi]: absent or outside, the error names the table and the key.
double bounded(scene::Table& t, const std::string& key, double lo, double hi, const char* unit, std::optional<double> fallback = {}) {
  // A length may carry its unit ("2.5 mm"), as in scenes.
  const std::optional<double> v = std::string_view(unit) == "m" ? t.length(key) : t.number(key);
  if (!v && fallback) return *fallback;
  if (!v) t.fail(key, "is missing", fmt::format("Give it in {} (between {:g} and {:g})", unit, lo, hi));
  if (*v < lo || *v > hi) t.fail(key, fmt::format("is {:g}, outside [{:g}, {:g}] {}", *v, lo, hi, unit), "Give it in SI units");
  return *v;
}

scene::Table required_table(scene::Table& root, const std::string& name, const std::string& holds) {
  std::optional<scene::Table> t = root.table(name);
  if (!t) root.fail(name, "is missing", "Add a [" + name + "] table with " + holds);
  return *t;
}

}  // namespace

MeasuredPowder read_measured_powder(const std::filesystem::path& file) {
  scene::TomlDocument doc = scene::TomlDocument::parse(file);
  scene::Table root = doc.root();
  MeasuredPowder m;
  m.source = file.string();
  scene::Table powder = required_table(root, "powder", "particle_diameter, material_density and apparent_density");
  m.particle_diameter = bounded(powder, "particle_diameter", 1e-6, 5e-3, "m");
  m.diameter_spread = bounded(powder, "diameter_spread", 0, 0.5, "(relative half-width)", m.diameter_spread);
  m.material_density = bounded(powder, "material_density", 100, 25000, "kg/m³");
  m.apparent_density = bounded(powder, "apparent_density", 1, m.material_density, "kg/m³ (at most the material density)");
  powder.finish();

  scene::Table repose = required_table(root, "repose", "angle_deg (a fixed-base funnel heap)");
  if (const auto method = repose.string("method"); method && *method != "fixed_base_heap")
    repose.fail("method", "is \"" + *method + "\"; only the fixed-base funnel heap is simulated", "Write method = \"fixed_base_heap\"");
  m.repose_deg = bounded(repose, "angle_deg", 5, 70, "°");
  m.repose_error_deg = bounded(repose, "angle_error_deg", 0.1, 10, "°", m.repose_error_deg);
  repose.finish();

  scene::Table flow = required_table(root, "flow", "orifice_diameter and mass_flow_rate (or mass and time)");
  m.orifice_diameter = bounded(flow, "orifice_diameter", 1e-4, 0.1, "m");
  m.funnel_half_angle_deg = bounded(flow, "funnel_half_angle_deg", 10, 90, "°", m.funnel_half_angle_deg);
  const bool as_rate = flow.has("mass_flow_rate");
  if (as_rate && (flow.has("mass") || flow.has("time")))
    flow.fail("mass_flow_rate", "is given with mass and time", "Give either mass_flow_rate or mass and time");
  m.flow_rate = as_rate ? bounded(flow, "mass_flow_rate", 1e-7, 100, "kg/s")
                        : bounded(flow, "mass", 1e-5, 100, "kg") / bounded(flow, "time", 0.1, 1e4, "s");
  m.flow_rate_error = bounded(flow, "rate_error", 0.001, 0.5, "(relative)", m.flow_rate_error);
  flow.finish();
  // Beverloo's law needs an orifice of several grains (docs/PHYSICS.md §3).
  if (m.orifice_diameter < 6 * m.particle_diameter)
    flow.fail("orifice_diameter", fmt::format("is {:.3g} grains wide", m.orifice_diameter / m.particle_diameter),
              "Give a test with an orifice at least 6 grains wide: a powder that flows at all through a narrower one is not "
              "free-flowing spheres");
  root.finish();
  return m;
}

bool is_measured_powder(const std::filesystem::path& file) {
  if (file.extension() != ".toml" || !std::filesystem::is_regular_file(file)) return false;
  scene::TomlDocument doc = scene::TomlDocument::parse(file);
  const scene::Table root = doc.root();
  return root.has("repose") || root.has("flow");
}

std::string measured_powder_toml(const MeasuredPowder& m) {
  return fmt::format(
      "[powder]\nparticle_diameter = {:.17g}\ndiameter_spread = {:.17g}\nmaterial_density = {:.17g}\napparent_density = {:.17g}\n\n"
      "[repose]\nmethod = \"fixed_base_heap\"\nangle_deg = {:.17g}\nangle_error_deg = {:.17g}\n\n"
      "[flow]\norifice_diameter = {:.17g}\nfunnel_half_angle_deg = {:.17g}\nmass_flow_rate = {:.17g}\nrate_error = {:.17g}\n",
      m.particle_diameter, m.diameter_spread, m.material_density, m.apparent_density, m.repose_deg, m.repose_error_deg,
      m.orifice_diameter, m.funnel_half_angle_deg, m.flow_rate, m.flow_rate_error);
}

}  // namespace studies
