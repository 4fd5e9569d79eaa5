#pragma once
// What a lab measured on its powder, as `diefill calibrate MEASURED.toml` reads it
// (docs/INTERFACE.md, "The measured powder"): the grain size and density, the apparent density,
// the angle of repose of a fixed-base funnel heap and the mass flow through a round orifice (a
// Hall or Carney funnel, ASTM B213 / ISO 4490, or a Flodex-type orifice). SI units.
#include <filesystem>
#include <string>

namespace studies {

struct MeasuredPowder {
  std::string source;               // the file, for messages
  double particle_diameter = 0;     // median [m]
  double diameter_spread = 0.1;     // relative half-width of a uniform distribution
  double material_density = 0;      // of the solid [kg/m³]
  double apparent_density = 0;      // poured [kg/m³] (ASTM B212, ISO 3923)
  double repose_deg = 0;            // the heap's angle [°]
  double repose_error_deg = 1.5;    // its standard error [°]: repeated tests of one powder differ by 1-2°
  double orifice_diameter = 0;      // [m]
  double funnel_half_angle_deg = 30;  // of the cone above it from the vertical: 30 for the Hall and Carney funnels, 90 a flat floor
  double flow_rate = 0;             // mass through the orifice [kg/s]
  double flow_rate_error = 0.03;    // relative standard error of the flow rate
  double solid_fraction() const { return apparent_density / material_density; }
};

// Reads and checks the file; throws InputError naming the file, the key and what to do.
MeasuredPowder read_measured_powder(const std::filesystem::path& file);

// Whether `file` is a measured powder (it has a [repose] or a [flow] table) rather than a scene.
bool is_measured_powder(const std::filesystem::path& file);

// The same as TOML, as read_measured_powder reads it (the round-trip test writes its twin's).
std::string measured_powder_toml(const MeasuredPowder& m);

}  // namespace studies
