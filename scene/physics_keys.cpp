#include "scene/physics_keys.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <set>

namespace scene {

namespace {

template <class T>
SceneKey<T> field(std::string_view table, std::string_view name, KeyType type, std::string_view unit, ValueRange range,
                  std::string_view meaning, double T::*member) {
  return {table, name, type, unit, range, {}, Shapes::settling, meaning,
          [member](const T& t) -> KeyValue { return t.*member; },
          [member](T& t, const KeyValue& v) { t.*member = std::get<double>(v); }};
}

}  // namespace

const KeyTable<dem::Material>& material_keys() {
  using M = dem::Material;
  static const KeyTable<M> keys = {
      {"materials", "name", KeyType::text, "", {}, {}, Shapes::settling,
       "what [[interactions]] and the scene call it; an entry named like a default (\"powder\", \"steel\") changes only the keys it gives",
       [](const M& m) -> KeyValue { return m.name; }, [](M& m, const KeyValue& v) { m.name = std::get<std::string>(v); }},
      field<M>("materials", "density", KeyType::number, "kg/m³", {100, 25000}, "of the solid grain material", &M::density),
      field<M>("materials", "youngs_modulus", KeyType::number, "Pa", {1e4, 1.2e12},
               "Hertz stiffness; softened powders keep overlaps near 1 % of the radius (checked each run)", &M::youngs_modulus),
      field<M>("materials", "poisson_ratio", KeyType::number, "", {0, 0.5, false, true}, "ν, with E the Hertz E* and G*", &M::poisson_ratio),
      field<M>("materials", "restitution", KeyType::number, "", {0.05, 1}, "of a head-on collision (damping calibrated to it)",
               &M::restitution),
      field<M>("materials", "sliding_friction", KeyType::number, "", {0, 10}, "Coulomb coefficient μ", &M::sliding_friction),
      field<M>("materials", "rolling_friction", KeyType::number, "", {0, 1}, "μ_r: rolling torque limit μ_r R* F_n",
               &M::rolling_friction),
      field<M>("materials", "cohesion_energy_density", KeyType::number, "J/m³", {0, 1e9}, "SJKR cohesion k (0: none)",
               &M::cohesion_energy_density),
  };
  return keys;
}

const KeyTable<InteractionEntry>& interaction_keys() {
  using I = InteractionEntry;
  // Besides these, `materials = ["a", "b"]` names the pair (read_materials).
  static const KeyTable<I> keys = {
      field<I>("interactions", "restitution", KeyType::number, "", {0.05, 1}, "replaces the geometric mean",
               &I::restitution),
      field<I>("interactions", "sliding_friction", KeyType::number, "", {0, 10}, "replaces the geometric mean",
               &I::sliding_friction),
      field<I>("interactions", "rolling_friction", KeyType::number, "", {0, 1}, "replaces the geometric mean",
               &I::rolling_friction),
  };
  return keys;
}

std::vector<std::string> read_materials(Table& root, dem::ModelSpec& spec, const std::filesystem::path& base) {
  // An entry naming a material the spec already has changes only the keys it gives (a scene
  // states what differs from the defaults); any other name adds a material.
  std::set<std::string> named;
  for (Table& t : root.tables("materials")) {
    const std::string name = t.string("name").value_or(fmt::format("material{}", spec.materials.size()));
    if (!named.insert(name).second)
      t.fail("name", "names material '" + name + "' a second time", "Give each [[materials]] entry its own name, or merge the two");
    const auto same_name = [&](const dem::Material& m) { return m.name == name; };
    auto found = std::find_if(spec.materials.begin(), spec.materials.end(), same_name);
    if (found == spec.materials.end()) found = spec.materials.insert(found, dem::Material{.name = name});
    read_entry(t, "materials", material_keys(), *found, base);
  }
  std::vector<std::string> names;
  for (const dem::Material& m : spec.materials) names.push_back(m.name);
  for (Table& t : root.tables("interactions")) {
    const auto pair = t.strings("materials");
    if (!pair || pair->size() != 2) t.fail("materials", "must name two materials", "Write materials = [\"a\", \"b\"]");
    const auto index = [&](const std::string& name) {
      const auto it = std::find(names.begin(), names.end(), name);
      if (it == names.end())
        t.fail("materials", "names material '" + name + "', which is not defined", "Define it in a [[materials]] table");
      return int(it - names.begin());
    };
    InteractionEntry entry;
    read_entry(t, "interactions", interaction_keys(), entry, base);
    dem::Interaction it;
    it.a = index((*pair)[0]);
    it.b = index((*pair)[1]);
    const auto given = [](double x) { return std::isnan(x) ? std::nullopt : std::optional<double>(x); };
    it.restitution = given(entry.restitution);
    it.sliding_friction = given(entry.sliding_friction);
    it.rolling_friction = given(entry.rolling_friction);
    spec.interactions.push_back(it);
  }
  return names;
}

std::string describe_materials(const dem::ModelSpec& spec) {
  std::string out;
  for (const dem::Material& m : spec.materials) out += "[[materials]]\n" + describe_table(material_keys(), "materials", m) + "\n";
  for (const dem::Interaction& it : spec.interactions) {
    out += "[[interactions]]\n";
    out += fmt::format("materials = [\"{}\", \"{}\"]\n", spec.materials[std::size_t(it.a)].name, spec.materials[std::size_t(it.b)].name);
    if (it.restitution) out += fmt::format("restitution = {}\n", *it.restitution);
    if (it.sliding_friction) out += fmt::format("sliding_friction = {}\n", *it.sliding_friction);
    if (it.rolling_friction) out += fmt::format("rolling_friction = {}\n", *it.rolling_friction);
    out += "\n";
  }
  return out;
}

}  // namespace scene
