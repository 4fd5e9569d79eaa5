#pragma once
// The keys every scene kind shares: [contact], the numerical keys of [simulation], and the
// entries of [[materials]] and [[interactions]] (docs/PHYSICS.md §2 for the laws, §5 for the time
// step), with their ranges.
#include <cmath>
#include <deque>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "dem/model.hpp"
#include "scene/scene_keys.hpp"

namespace scene {

// The entries of [[materials]].
const KeyTable<dem::Material>& material_keys();

// An [[interactions]] entry: a pair of materials and the values that replace their mixing rule.
struct InteractionEntry {
  double restitution = std::numeric_limits<double>::quiet_NaN();  // NaN: the mixing rule's
  double sliding_friction = std::numeric_limits<double>::quiet_NaN();
  double rolling_friction = std::numeric_limits<double>::quiet_NaN();
};
const KeyTable<InteractionEntry>& interaction_keys();

// Appends the [contact] keys and the numerical [simulation] keys (time step, its fraction, the
// impact speed, gravity, skin, the stop overlap) of the spec that `spec` reaches in a Target.
template <class Target>
void add_physics_keys(KeyTable<Target>& keys, dem::ModelSpec& (*spec)(Target&), Shapes shapes) {
  const auto of = [spec](const Target& t) -> const dem::ModelSpec& { return spec(const_cast<Target&>(t)); };
  // One key per slot, its choices the laws the registry holds (dem/contact_laws.hpp), its meaning
  // theirs; kept as long as the key tables, which live for the program.
  static std::deque<std::string> law_meanings;
  const auto law = [&](dem::LawSlot slot, std::string_view what) {
    const std::vector<std::string_view> choices = dem::slot_law_names(slot);
    std::string& meaning = law_meanings.emplace_back(what);
    for (const dem::SlotLaw& l : dem::slot_laws())
      if (l.slot == slot)
        meaning.append(meaning.back() == ':' ? " " : "; ").append(l.name).append(": ").append(l.meaning)
            .append(l.reads.empty() ? "" : " (reads ").append(l.reads).append(l.reads.empty() ? "" : ")");
    keys.push_back({"contact", dem::law_slot_names[std::size_t(slot)], KeyType::choice, "", {}, choices, shapes, meaning,
                    [of, slot](const Target& t) -> KeyValue { return of(t).law[slot]; },
                    [spec, slot](Target& t, const KeyValue& v) { spec(t).law[slot] = std::get<std::string>(v); }});
  };
  law(dem::LawSlot::normal, "the normal force:");
  law(dem::LawSlot::tangential, "the tangential force:");
  law(dem::LawSlot::rolling, "rolling resistance:");
  law(dem::LawSlot::cohesion, "cohesion:");
  const auto number = [&](std::string_view table, std::string_view name, KeyType type, std::string_view unit, ValueRange range,
                          std::string_view meaning, auto get, auto set) {
    keys.push_back({table, name, type, unit, range, {}, shapes, meaning,
                    [of, get](const Target& t) -> KeyValue { return get(of(t)); },
                    [spec, set](Target& t, const KeyValue& v) { set(spec(t), v); }});
  };
  number("contact", "linear_stiffness", KeyType::number, "N/m", zero_or(1e-3, 1e9),
         "the real powder's spring for the linear law; coarse grains get α times it (docs/PHYSICS.md §4)",
         [](const dem::ModelSpec& s) { return s.linear_stiffness; },
         [](dem::ModelSpec& s, const KeyValue& v) { s.linear_stiffness = std::get<double>(v); });
  number("simulation", "time_step", KeyType::number_or_auto, "s", {1e-9, 1e-3},
         "\"auto\": a fraction of the smaller of the Rayleigh and Hertz collision times",
         [](const dem::ModelSpec& s) { return s.time_step.value_or(std::numeric_limits<double>::quiet_NaN()); },
         [](dem::ModelSpec& s, const KeyValue& v) {
           const double dt = std::get<double>(v);
           s.time_step = std::isnan(dt) ? std::nullopt : std::optional<double>(dt);
         });
  number("simulation", "time_step_fraction", KeyType::number, "", {1e-3, 1},
         "of the stable limit, when the step is automatic (docs/PHYSICS.md §5)",
         [](const dem::ModelSpec& s) { return s.time_step_fraction; },
         [](dem::ModelSpec& s, const KeyValue& v) { s.time_step_fraction = std::get<double>(v); });
  number("simulation", "max_impact_speed", KeyType::number, "m/s", {1e-3, 100},
         "for the Hertz collision time; the pipeline raises it to sqrt(2 g depth) + shoe speed for deeper dies",
         [](const dem::ModelSpec& s) { return s.max_impact_speed; },
         [](dem::ModelSpec& s, const KeyValue& v) { s.max_impact_speed = std::get<double>(v); });
  number("simulation", "gravity", KeyType::vec3, "m/s²", {-100, 100}, "gravitational acceleration",
         [](const dem::ModelSpec& s) { return s.gravity; },
         [](dem::ModelSpec& s, const KeyValue& v) { s.gravity = std::get<dem::Vec3>(v); });
  number("simulation", "skin", KeyType::number_or_auto, "m", {1e-7, 0.01},
         "neighbour-list skin; \"auto\": half the largest grain radius",
         [](const dem::ModelSpec& s) { return s.skin.value_or(std::numeric_limits<double>::quiet_NaN()); },
         [](dem::ModelSpec& s, const KeyValue& v) {
           const double skin = std::get<double>(v);
           s.skin = std::isnan(skin) ? std::nullopt : std::optional<double>(skin);
         });
  number("simulation", "stop_overlap", KeyType::number, "", {0.01, 0.5},
         "stop (exit status 3) when an overlap exceeds this fraction of a radius: flowing grains overlap 1-2 %, a time "
         "step past the stable limit goes far beyond",
         [](const dem::ModelSpec& s) { return s.stop_overlap; },
         [](dem::ModelSpec& s, const KeyValue& v) { s.stop_overlap = std::get<double>(v); });
}

// Reads [contact] (through `keys`, as the caller's table), [[materials]] (replacing the spec's
// materials when given) and [[interactions]]; returns the material names in order.
std::vector<std::string> read_materials(Table& root, dem::ModelSpec& spec, const std::filesystem::path& base);
// The [[materials]] and [[interactions]] of a spec as TOML, each value with its meaning.
std::string describe_materials(const dem::ModelSpec& spec);

}  // namespace scene
