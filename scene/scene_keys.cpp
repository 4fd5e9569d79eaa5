#include "scene/scene_keys.hpp"

#include <fmt/core.h>

#include <cmath>
#include <limits>

#include "core/error.hpp"

namespace scene {

bool ValueRange::contains(double x) const {
  if (!std::isfinite(x)) return false;
  if (or_zero && x == 0) return true;
  const bool above = lo_open ? x > lo : x >= lo;
  const bool below = hi_open ? x < hi : x <= hi;
  return above && below;
}

std::string ValueRange::text() const {
  return fmt::format("{}{}{}, {}{}", or_zero ? "0 or " : "", lo_open ? "(" : "[", lo, hi, hi_open ? ")" : "]");
}

namespace {
// "must lie in [a, b]" or "must be 0 or lie in [a, b]".
std::string range_rule(const ValueRange& range) {
  ValueRange interval = range;
  interval.or_zero = false;
  return (range.or_zero ? "must be 0 or lie in " : "must lie in ") + interval.text();
}
}  // namespace

std::string toml_value(const KeyValue& value, KeyType type) {
  if (const double* x = std::get_if<double>(&value)) {
    if (type == KeyType::number_or_auto && std::isnan(*x)) return "\"auto\"";
    if (type == KeyType::integer) return fmt::format("{}", std::int64_t(*x));
    // Shortest form that reads back to the same double: exact in cache keys, plain to read.
    return fmt::format("{}", *x);
  }
  if (const bool* b = std::get_if<bool>(&value)) return *b ? "true" : "false";
  if (const std::string* t = std::get_if<std::string>(&value)) {
    std::string quoted = "\"";
    for (char c : *t) quoted += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
    return quoted + "\"";
  }
  const dem::Vec3& v = std::get<dem::Vec3>(value);
  return fmt::format("[{}, {}, {}]", v.x(), v.y(), v.z());
}

std::optional<KeyValue> read_value(Table& t, std::string_view name, KeyType type, std::string_view unit,
                                   const std::filesystem::path& base) {
  const std::string key(name);
  const bool length = unit == "m";
  switch (type) {
    case KeyType::number:
      if (auto x = length ? t.length(key) : t.number(key)) return *x;
      return std::nullopt;
    case KeyType::number_or_auto: {
      bool automatic = false;
      const std::optional<double> x = length ? t.length_or(key, "auto", automatic) : t.number_or(key, "auto", automatic);
      if (automatic) return std::numeric_limits<double>::quiet_NaN();
      if (x) return *x;
      return std::nullopt;
    }
    case KeyType::integer:
      if (auto n = t.integer(key)) return double(*n);
      return std::nullopt;
    case KeyType::boolean:
      if (auto b = t.boolean(key)) return *b;
      return std::nullopt;
    case KeyType::text:
    case KeyType::choice:
      if (auto s = t.string(key)) return *s;
      return std::nullopt;
    case KeyType::path:
      if (auto s = t.string(key)) return s->empty() ? std::string() : (base / *s).string();
      return std::nullopt;
    case KeyType::vec3:
      if (auto v = t.vec3(key)) return *v;
      return std::nullopt;
  }
  return std::nullopt;
}

void check_value(Table& where, std::string_view name, KeyType type, const ValueRange& range,
                 const std::vector<std::string_view>& choices, const KeyValue& value, std::string_view unit) {
  const std::string key(name);
  const std::string in_unit = unit.empty() ? std::string() : fmt::format(" [{}]", unit);
  auto out_of_range = [&](const std::string& got) {
    where.fail(key, fmt::format("{}{}, got {}", range_rule(range), in_unit, got),
               fmt::format("Give a value in {} (`diefill scene` prints every key with its range)", range.text()));
  };
  switch (type) {
    case KeyType::number:
    case KeyType::integer: {
      const double x = std::get<double>(value);
      if (!range.contains(x)) out_of_range(fmt::format("{}", x));
      return;
    }
    case KeyType::number_or_auto: {
      const double x = std::get<double>(value);
      if (!std::isnan(x) && !range.contains(x)) out_of_range(fmt::format("{}", x));
      return;
    }
    case KeyType::vec3: {
      const dem::Vec3& v = std::get<dem::Vec3>(value);
      for (int k = 0; k < 3; ++k)
        if (!range.contains(v[k])) out_of_range(fmt::format("[{}, {}, {}]", v.x(), v.y(), v.z()));
      return;
    }
    case KeyType::choice: {
      const std::string& s = std::get<std::string>(value);
      std::string allowed;
      for (std::string_view c : choices) {
        if (s == c) return;
        allowed += (allowed.empty() ? "" : ", ") + std::string(c);
      }
      where.fail(key, fmt::format("'{}' is not one of {}", s, allowed), "Use one of: " + allowed);
    }
    case KeyType::boolean:
    case KeyType::text:
    case KeyType::path:
      return;
  }
}

std::string_view type_name(KeyType type) {
  switch (type) {
    case KeyType::number: return "number";
    case KeyType::number_or_auto: return "number or \"auto\"";
    case KeyType::integer: return "integer";
    case KeyType::boolean: return "boolean";
    case KeyType::text: return "text";
    case KeyType::choice: return "choice";
    case KeyType::path: return "path";
    case KeyType::vec3: return "[x, y, z]";
  }
  return "";
}

std::string_view shapes_name(Shapes shapes) {
  switch (shapes) {
    case Shapes::die: return "die";
    case Shapes::settling: return "settled shoe";
    case Shapes::run: return "run";
    case Shapes::nothing: return "-";
  }
  return "";
}

}  // namespace scene
