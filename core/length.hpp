#pragma once
// A length written with its unit, accepted wherever a length is typed: the command line's length
// flags (a bare number there is millimetres, as their help says) and the scene's length keys (a
// bare number there is metres). "0.2mm", "0.2 mm", "2e-4m", "200um" (or µm), "0.01in"
// (docs/INTERFACE.md, "Lengths").
#include <optional>
#include <string_view>

namespace diefill {

struct Length {
  double value;
  double metres_per_unit, millimetres_per_unit;  // both exact for the unit: no conversion through the other
  double metres() const { return value * metres_per_unit; }
  double millimetres() const { return value * millimetres_per_unit; }
};

// nullopt unless `text` is a finite number followed by one of those units (a bare number has none).
std::optional<Length> parse_length(std::string_view text);

}  // namespace diefill
