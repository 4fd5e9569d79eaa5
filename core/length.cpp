#include "core/length.hpp"

#include <charconv>
#include <cmath>
#include <string>

namespace diefill {

namespace {

struct Unit {
  std::string_view name;
  double metres, millimetres;
};
constexpr Unit units[] = {{"m", 1.0, 1000.0}, {"mm", 1e-3, 1.0}, {"um", 1e-6, 1e-3}, {"µm", 1e-6, 1e-3}, {"in", 0.0254, 25.4}};

std::string_view trimmed(std::string_view text) {
  while (!text.empty() && text.front() == ' ') text.remove_prefix(1);
  while (!text.empty() && text.back() == ' ') text.remove_suffix(1);
  return text;
}

}  // namespace

std::optional<Length> parse_length(std::string_view text) {
  text = trimmed(text);
  double value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || !std::isfinite(value)) return std::nullopt;
  const std::string_view unit = trimmed(text.substr(std::size_t(end - text.data())));
  for (const Unit& u : units)
    if (unit == u.name) return Length{value, u.metres, u.millimetres};
  return std::nullopt;
}

}  // namespace diefill
