#pragma once
// One table of scene keys: each key's place in the scene file, type, unit, default, range and
// meaning, and which cached result it shapes. The table drives the loader (every value checked
// against its range at load time, so `diefill scene` refuses what `diefill run` would), `diefill
// scene` (each value printed with its meaning), the generated key reference of docs/INTERFACE.md
// and the settled shoe's cache key (the keys that shape it, hashed).
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <functional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "dem/types.hpp"
#include "scene/toml_reader.hpp"

namespace scene {

enum class KeyType : std::uint8_t {
  number,          // a real number in the key's unit
  number_or_auto,  // a number, or the word "auto" (held as NaN)
  integer,
  boolean,
  text,            // free text
  choice,          // one of the key's choices
  path,            // a file, relative to the scene file's folder; "" for none
  vec3,            // [x, y, z] in the key's unit
};

// Which stage's result a key shapes: a cached result is reused only while every key that shapes
// it is unchanged.
enum class Shapes : std::uint8_t {
  die,       // the die's mesh stage (cached by the options it derives from them)
  settling,  // the settled shoe, and everything after it
  run,       // the shoe's pass and what follows
  nothing,   // where and how results are written, and how fast: never the result
};

// Closed unless marked open; integers and the components of a vec3 are checked alike. A key whose
// 0 means "derived" or "off" (density.voxel = 0: two grain diameters) allows 0 besides the
// interval, which starts at the smallest value that means something: an open bound at 0 lets
// 1e-300 through, and such a value only shows as an overflow after the whole DEM (issue 44).
struct ValueRange {
  double lo = 0, hi = 0;
  bool lo_open = false, hi_open = false;
  bool or_zero = false;
  bool contains(double x) const;
  std::string text() const;  // "(0, 4]", "0 or [1e-05, 0.05]"
};
constexpr ValueRange zero_or(double lo, double hi) { return {lo, hi, false, false, true}; }

// A value as the table holds it: a number (also an integer key's, exactly), a flag, text (also a
// choice or a path) or a 3-vector.
using KeyValue = std::variant<double, bool, std::string, dem::Vec3>;

template <class Target>
struct SceneKey {
  std::string_view table;  // "shoe", "powder.shape"
  std::string_view name;   // "length"
  KeyType type;
  std::string_view unit;   // "m", "m/s", "" when dimensionless
  ValueRange range;        // numbers, integers, vec3 components
  std::vector<std::string_view> choices;  // choice keys
  Shapes shapes;
  std::string_view meaning;  // what the key is and why its default: one line
  std::function<KeyValue(const Target&)> get;
  std::function<void(Target&, const KeyValue&)> set;

  std::string path() const { return std::string(table) + "." + std::string(name); }
};

template <class Target>
using KeyTable = std::vector<SceneKey<Target>>;

std::string toml_value(const KeyValue& value, KeyType type);
// Checks a value read for `key_path` against its type's rules and range; fails through `where`.
void check_value(Table& where, std::string_view name, KeyType type, const ValueRange& range,
                 const std::vector<std::string_view>& choices, const KeyValue& value, std::string_view unit);
// Reads one value of the given type from `t` (nullopt when absent); wrong types fail.
// A number whose unit is "m" is a length: it may also be written with its unit ("0.2 mm").
std::optional<KeyValue> read_value(Table& t, std::string_view name, KeyType type, std::string_view unit,
                                   const std::filesystem::path& base);
std::string_view type_name(KeyType type);
std::string_view shapes_name(Shapes shapes);

// Reads the keys of `keys` that lie in `t` (the table `table_path`).
template <class Target>
void read_table_keys(Table& t, std::string_view table_path, const KeyTable<Target>& keys, Target& target,
                     const std::filesystem::path& base) {
  for (const SceneKey<Target>& key : keys) {
    if (key.table != table_path) continue;
    const std::optional<KeyValue> value = read_value(t, key.name, key.type, key.unit, base);
    if (!value) continue;
    check_value(t, key.name, key.type, key.range, key.choices, *value, key.unit);
    key.set(target, *value);
  }
}

// Reads every key of `keys` that the scene gives, checking its type and range (InputError naming
// the key, with file and line); keys absent keep their value in `target`. Each table the keys
// name is then finished (an unknown key is an error), except those in `open_tables`, whose other
// keys the caller reads and finishes. Paths are resolved against `base`. One level of nesting:
// "powder.shape" is the table `shape` inside [powder].
template <class Target>
void read_keys(Table& root, const KeyTable<Target>& keys, Target& target, const std::filesystem::path& base,
               const std::vector<std::string_view>& open_tables = {}) {
  std::vector<std::string_view> tops;
  for (const SceneKey<Target>& key : keys) {
    const std::string_view top = key.table.substr(0, key.table.find('.'));
    if (std::find(tops.begin(), tops.end(), top) == tops.end()) tops.push_back(top);
  }
  for (std::string_view top : tops) {
    std::optional<Table> t = root.table(std::string(top));
    if (!t) continue;
    read_table_keys(*t, top, keys, target, base);
    std::vector<std::string_view> nested;
    for (const SceneKey<Target>& key : keys)
      if (key.table.size() > top.size() && key.table.substr(0, top.size() + 1) == std::string(top) + "." &&
          std::find(nested.begin(), nested.end(), key.table) == nested.end())
        nested.push_back(key.table);
    for (std::string_view inner : nested)
      if (std::optional<Table> sub = t->table(std::string(inner.substr(top.size() + 1)))) {
        read_table_keys(*sub, inner, keys, target, base);
        sub->finish();
      }
    if (std::find(open_tables.begin(), open_tables.end(), top) == open_tables.end()) t->finish();
  }
}

// The keys of one [[array]] entry (their table is the array's name), read from `entry`, finished.
template <class Target>
void read_entry(Table& entry, std::string_view array, const KeyTable<Target>& keys, Target& target,
                const std::filesystem::path& base) {
  read_table_keys(entry, array, keys, target, base);
  entry.finish();
}

// `key = value  # [unit] meaning` for every key of `table`, in the table's order; path keys left
// empty are left out.
template <class Target>
std::string describe_table(const KeyTable<Target>& keys, std::string_view table, const Target& target) {
  std::string out;
  for (const SceneKey<Target>& key : keys) {
    if (key.table != table) continue;
    const KeyValue value = key.get(target);
    if (key.type == KeyType::path && std::get<std::string>(value).empty()) continue;
    std::string line = std::string(key.name) + " = " + toml_value(value, key.type);
    line.resize(std::max<std::size_t>(line.size() + 1, 32), ' ');
    // Appended piece by piece: `"[" + std::string(unit)` inlines to a copy GCC 12 takes for an
    // overlapping one (-Wrestrict, a false positive; warnings are errors).
    std::string comment;
    if (!key.unit.empty()) comment.append("[").append(key.unit).append("] ");
    comment.append(key.meaning);
    while (!comment.empty() && comment.back() == ' ') comment.pop_back();
    out += line + "# " + comment + "\n";
  }
  return out;
}

// The values of the keys that shape `what`, exactly (toml_value writes numbers in full
// precision), one `table.key=value` per line.
template <class Target>
std::string shaping_values(const KeyTable<Target>& keys, Shapes what, const Target& target) {
  std::string out;
  for (const SceneKey<Target>& key : keys)
    if (key.shapes == what) out += key.path() + "=" + toml_value(key.get(target), key.type) + "\n";
  return out;
}

// A Markdown table of the keys: key, type, unit, default (from `defaults`), range, what it
// shapes, meaning. `prefix` goes before each key's path ("materials[]." for an array's entries).
template <class Target>
std::string markdown_table(const KeyTable<Target>& keys, const Target& defaults, std::string_view prefix = "") {
  std::string out = "| key | type | unit | default | range | shapes | meaning |\n|---|---|---|---|---|---|---|\n";
  for (const SceneKey<Target>& key : keys) {
    std::string range;
    if (key.type == KeyType::choice) {
      for (std::string_view c : key.choices) range += (range.empty() ? "" : ", ") + std::string("`") + std::string(c) + "`";
    } else if (key.type == KeyType::number || key.type == KeyType::number_or_auto || key.type == KeyType::integer ||
               key.type == KeyType::vec3) {
      range = key.range.text();
    }
    std::string value = toml_value(key.get(defaults), key.type);
    if (key.type == KeyType::path && value == "\"\"") value = "(none)";
    out += "| `" + std::string(prefix) + (prefix.empty() ? key.path() : std::string(key.name)) + "` | " +
           std::string(type_name(key.type)) + " | " + std::string(key.unit) + " | `" + value + "` | " + range + " | " +
           std::string(shapes_name(key.shapes)) + " | " + std::string(key.meaning) + " |\n";
  }
  return out;
}

}  // namespace scene
