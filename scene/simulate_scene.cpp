#include "scene/simulate_scene.hpp"

#include <fmt/core.h>

#include <algorithm>

#include "core/error.hpp"
#include "dem/io.hpp"
#include "scene/physics_keys.hpp"
#include "scene/toml_reader.hpp"

namespace scene {

namespace fs = std::filesystem;

namespace {

using S = SimulationScene;

// Ranges as the pipeline's keys (pipeline_scene.cpp): a desk-sized rig, not a quarry.
constexpr ValueRange lengths{-1e3, 1e3}, speeds{-100, 100}, spins{-1e5, 1e5};

template <class T>
SceneKey<T> value_key(std::string_view table, std::string_view name, KeyType type, std::string_view unit, ValueRange range,
                      std::string_view meaning, auto member) {
  using V = std::remove_cvref_t<decltype(std::declval<T&>().*member)>;
  return {table, name, type, unit, range, {}, Shapes::settling, meaning,
          [member](const T& t) -> KeyValue {
            if constexpr (std::is_same_v<V, fs::path>) return (t.*member).string();
            else if constexpr (std::is_integral_v<V> && !std::is_same_v<V, bool>) return double(t.*member);
            else return t.*member;
          },
          [member](T& t, const KeyValue& v) {
            if constexpr (std::is_same_v<V, fs::path>) t.*member = std::get<std::string>(v);
            else if constexpr (std::is_integral_v<V> && !std::is_same_v<V, bool>) t.*member = V(std::get<double>(v));
            else t.*member = std::get<V>(v);
          }};
}

dem::ModelSpec& spec_of(S& s) { return s.spec; }

KeyTable<S> make_simulation_keys() {
  KeyTable<S> k = {
      value_key<S>("simulation", "duration", KeyType::number, "s", {0, 1e4, true}, "simulated time", &S::duration),
  };
  add_physics_keys<S>(k, spec_of, Shapes::settling);
  k.push_back(value_key<S>("simulation", "seed", KeyType::integer, "", {0, 9007199254740991.0}, "", &S::seed));
  k.push_back(value_key<S>("simulation", "threads", KeyType::integer, "", {0, 4096}, "0: all cores", &S::threads));
  k.back().shapes = Shapes::nothing;
  return k;
}

const KeyTable<S>& simulation_keys() {
  static const KeyTable<S> keys = make_simulation_keys();
  return keys;
}

const KeyTable<SimulationOutput>& output_keys() {
  using O = SimulationOutput;
  static const KeyTable<O> keys = {
      value_key<O>("output", "directory", KeyType::text, "", {}, "relative to the working folder", &O::directory),
      value_key<O>("output", "trajectory", KeyType::boolean, "", {}, "particles CSV at every trajectory_every", &O::trajectory),
      value_key<O>("output", "trajectory_every", KeyType::number, "s", {0, 100, true}, "", &O::trajectory_every),
      value_key<O>("output", "snapshot_every", KeyType::number, "s", {0, 100}, "VTU snapshots; 0: none", &O::snapshot_every),
  };
  return keys;
}

const KeyTable<dem::Box3>& domain_keys() {
  static const KeyTable<dem::Box3> keys = {
      value_key<dem::Box3>("domain", "lo", KeyType::vec3, "m", lengths, "grains leaving the box are lost (counted)", &dem::Box3::lo),
      value_key<dem::Box3>("domain", "hi", KeyType::vec3, "m", lengths, "default: the particles' box, enlarged", &dem::Box3::hi),
  };
  return keys;
}

struct ParticlesEntry {
  std::string file, material;
};

const KeyTable<ParticlesEntry>& particles_keys() {
  static const KeyTable<ParticlesEntry> keys = {
      value_key<ParticlesEntry>("particles", "file", KeyType::path, "", {}, "the particles CSV (docs/INTERFACE.md)",
                                &ParticlesEntry::file),
      value_key<ParticlesEntry>("particles", "material", KeyType::text, "", {}, "the first material when absent",
                                &ParticlesEntry::material),
  };
  return keys;
}

// [[walls]] entries, read into a plain entry first.
struct WallEntry {
  std::string type = "plane", material, file, units = "mm", role = "cavity";
  dem::Vec3 point = dem::Vec3::Zero(), normal = dem::Vec3::UnitZ();
};

const KeyTable<WallEntry> wall_keys() {
  using W = WallEntry;
  static const KeyTable<W> keys = [] {
    KeyTable<W> k = {
        value_key<W>("walls", "type", KeyType::choice, "", {}, "an infinite plane or a mesh", &W::type),
        value_key<W>("walls", "material", KeyType::text, "", {}, "the first material when absent", &W::material),
        value_key<W>("walls", "point", KeyType::vec3, "m", lengths, "plane: a point on it", &W::point),
        value_key<W>("walls", "normal", KeyType::vec3, "", {-1e3, 1e3}, "plane: towards the particles", &W::normal),
        value_key<W>("walls", "file", KeyType::path, "", {}, "mesh: the wall's mesh", &W::file),
        value_key<W>("walls", "units", KeyType::choice, "", {}, "mesh: the file's length unit", &W::units),
        value_key<W>("walls", "role", KeyType::choice, "", {}, "mesh: cavity, tool or container", &W::role),
    };
    k[0].choices = {"plane", "mesh"};
    k[5].choices = {"mm", "m", "in"};
    k[6].choices = {"cavity", "tool", "container"};
    return k;
  }();
  return keys;
}

const KeyTable<dem::Motion>& motion_keys() {
  using M = dem::Motion;
  static const KeyTable<M> keys = {
      value_key<M>("motion", "velocity", KeyType::vec3, "m/s", speeds, "constant velocity (same as start_velocity)",
                   &M::start_velocity),
      value_key<M>("motion", "start_velocity", KeyType::vec3, "m/s", speeds, "", &M::start_velocity),
      value_key<M>("motion", "start_position", KeyType::vec3, "m", lengths, "of the wall frame's origin at t = 0",
                   &M::start_position),
      value_key<M>("motion", "angular_velocity", KeyType::vec3, "rad/s", spins, "about the pivot", &M::angular_velocity),
      value_key<M>("motion", "pivot", KeyType::vec3, "m", lengths, "in the wall frame", &M::pivot),
  };
  return keys;
}

const KeyTable<dem::Motion::Segment>& segment_keys() {
  using G = dem::Motion::Segment;
  static const KeyTable<G> keys = {
      value_key<G>("segments", "duration", KeyType::number, "s", {0, 1e4, true}, "", &G::duration),
      value_key<G>("segments", "acceleration", KeyType::vec3, "m/s²", {-1e4, 1e4}, "", &G::acceleration),
  };
  return keys;
}

dem::Motion read_motion(Table& t, const fs::path& base) {
  dem::Motion m;
  for (Table& s : t.tables("segments")) {
    dem::Motion::Segment seg;
    if (!s.has("duration")) s.fail("duration", "is missing", "Give the segment's duration [s]");
    read_entry(s, "segments", segment_keys(), seg, base);
    m.segments.push_back(seg);
  }
  read_entry(t, "motion", motion_keys(), m, base);
  return m;
}

int material_index(const std::vector<std::string>& names, const std::string& name, Table& where, const std::string& key) {
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end())
    where.fail(key, "names material '" + name + "', which is not defined", "Define it in a [[materials]] table");
  return int(it - names.begin());
}

// The domain defaults to the particles' box, generously enlarged.
dem::Box3 default_domain(const dem::State& state) {
  dem::Vec3 lo = state.x.front(), hi = lo;
  double r_max = 0;
  for (std::size_t i = 0; i < state.size(); ++i)
    lo = lo.cwiseMin(state.x[i]), hi = hi.cwiseMax(state.x[i]), r_max = std::max(r_max, state.radius[i]);
  const dem::Vec3 margin = dem::Vec3::Constant(std::max(0.5 * (hi - lo).maxCoeff(), 20 * r_max));
  return {lo - margin, hi + margin};
}

void read_walls(Table& root, SimulationScene& scene, const std::vector<std::string>& names, const fs::path& base) {
  for (Table& w : root.tables("walls")) {
    WallEntry entry;
    entry.material = names.front();
    std::optional<dem::Motion> motion;
    if (std::optional<Table> m = w.table("motion")) motion = read_motion(*m, base);
    read_entry(w, "walls", wall_keys(), entry, base);
    const int material = material_index(names, entry.material, w, "material");
    if (entry.type == "plane") {
      if (entry.normal.norm() == 0) w.fail("normal", "must not be zero", "Give the direction towards the particles");
      scene.spec.planes.push_back({entry.point, entry.normal, material, w.path()});
      continue;
    }
    if (entry.file.empty()) w.fail("file", "is missing", "Name the wall's mesh");
    scene.mesh_walls.push_back({w.path(), entry.file, entry.units, entry.role, material, motion});
  }
}

}  // namespace

SimulationScene load_simulation_scene(const fs::path& path, const std::vector<std::string>& overrides) {
  TomlDocument doc = TomlDocument::parse(path);
  doc.apply_overrides(overrides);
  Table root = doc.root();
  SimulationScene scene;
  scene.source = path.string();
  const fs::path base = path.parent_path();
  // One material when the scene names none; a scene's own materials start from nothing.
  scene.spec.materials.clear();
  if (!root.has("materials")) scene.spec.materials.push_back(dem::Material{.name = "default"});
  read_keys(root, simulation_keys(), scene, base);
  read_keys(root, output_keys(), scene.output, base);
  const std::vector<std::string> names = read_materials(root, scene.spec, base);

  if (!root.has("particles")) root.fail("particles", "is missing", "Add [particles] with file = \"particles.csv\"");
  ParticlesEntry particles{"", names.front()};
  read_keys(root, particles_keys(), particles, base);
  if (particles.file.empty()) root.table("particles")->fail("file", "is missing", "Name the particles CSV");
  std::optional<Table> particles_table = root.table("particles");
  const int material = material_index(names, particles.material, *particles_table, "material");
  scene.state = dem::read_particles_csv(particles.file, material, scene.spec.materials[std::size_t(material)].density);
  scene.spec.domain = default_domain(scene.state);
  read_keys(root, domain_keys(), scene.spec.domain, base);
  read_walls(root, scene, names, base);
  root.finish();
  return scene;
}

}  // namespace scene
