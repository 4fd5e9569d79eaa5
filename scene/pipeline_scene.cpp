#include "scene/pipeline_scene.hpp"

#include <fmt/core.h>

#include <algorithm>

#include "core/error.hpp"
#include "scene/physics_keys.hpp"
#include "scene/toml_reader.hpp"

namespace scene {

namespace {

using P = PipelineScene;
using K = SceneKey<P>;

// The value a key reads and writes, as a reference from the scene: in the settings of its table's
// stage (s.*group.*m), or the scene's own (s.*m).
template <class Group, class T>
auto member(Group P::*group, T Group::*m) {
  return [group, m](auto& s) -> auto& { return s.*group.*m; };
}
template <class T>
auto member(T P::*m) {
  return [m](auto& s) -> auto& { return s.*m; };
}

template <class Member>
K number(std::string_view table, std::string_view name, std::string_view unit, ValueRange range, Shapes shapes,
         std::string_view meaning, Member f) {
  return {table, name, KeyType::number, unit, range, {}, shapes, meaning,
          [f](const P& s) -> KeyValue { return double(f(s)); },
          [f](P& s, const KeyValue& v) { f(s) = std::get<double>(v); }};
}

template <class Member>
K integer(std::string_view table, std::string_view name, ValueRange range, Shapes shapes, std::string_view meaning, Member f) {
  return {table, name, KeyType::integer, "", range, {}, shapes, meaning,
          [f](const P& s) -> KeyValue { return double(f(s)); },
          [f](P& s, const KeyValue& v) { f(s) = std::remove_reference_t<decltype(f(s))>(std::get<double>(v)); }};
}

template <class Member>
K flag(std::string_view table, std::string_view name, Shapes shapes, std::string_view meaning, Member f) {
  return {table, name, KeyType::boolean, "", {}, {}, shapes, meaning,
          [f](const P& s) -> KeyValue { return bool(f(s)); },
          [f](P& s, const KeyValue& v) { f(s) = std::get<bool>(v); }};
}

template <class Member>
K text(std::string_view table, std::string_view name, KeyType type, Shapes shapes, std::string_view meaning, Member f) {
  return {table, name, type, "", {}, {}, shapes, meaning,
          [f](const P& s) -> KeyValue { return std::filesystem::path(f(s)).string(); },
          [f](P& s, const KeyValue& v) { f(s) = std::remove_reference_t<decltype(f(s))>(std::get<std::string>(v)); }};
}

// A choice read into the enum (or unit, or direction) of the module that acts on it, from that
// module's table of names (core/choice.hpp): the scene's text is checked against the names once,
// at load (check_value, before `set`), and no stage parses it again.
template <class Value, class Member>
K choice(std::string_view table, std::string_view name, std::vector<diefill::Choice<Value>> options, Shapes shapes,
         std::string_view meaning, Member f) {
  std::vector<std::string_view> names;
  for (const auto& option : options) names.push_back(option.name);
  const auto find = [options](const auto& matches) {
    for (const auto& option : options)
      if (matches(option)) return option;
    throw std::logic_error("a scene choice holds a value or a name its key does not list");
  };
  return {table, name, KeyType::choice, "", {}, std::move(names), shapes, meaning,
          [f, find](const P& s) -> KeyValue { return std::string(find([&](const auto& o) { return o.value == f(s); }).name); },
          [f, find](P& s, const KeyValue& v) { f(s) = find([&](const auto& o) { return o.name == std::get<std::string>(v); }).value; }};
}

template <class Value, std::size_t N>
std::vector<diefill::Choice<Value>> options_of(const std::array<diefill::Choice<Value>, N>& table) {
  return {table.begin(), table.end()};
}

// The table's choices after "auto": unset, found or guessed by the stage.
template <class Value, std::size_t N>
std::vector<diefill::Choice<std::optional<Value>>> auto_or(const std::array<diefill::Choice<Value>, N>& table) {
  std::vector<diefill::Choice<std::optional<Value>>> options = {{"auto", std::nullopt}};
  for (const auto& c : table) options.push_back({c.name, c.value});
  return options;
}

dem::ModelSpec& spec_of(P& s) { return s.spec; }

constexpr double metre_range_hi = 1.0;  // the die table is a desk, not a quarry

KeyTable<P> make_pipeline_keys() {
  const Shapes die = Shapes::die, settling = Shapes::settling, run = Shapes::run, nothing = Shapes::nothing;
  KeyTable<P> k = {
      text("die", "file", KeyType::path, die, "the die's cavity mesh (relative to the scene file)", member(&P::die, &DieSettings::file)),
      choice("die", "units", auto_or(geometry::length_units), die,
             "the mesh file's length unit (files store none); auto: guessed from its size, 3 or more across mm, 1 to 3 "
             "inches, under 1 metres (a warning says so unless mm)",
             member(&P::die, &DieSettings::units)),
      choice("die", "up", auto_or(mesh::directions), die,
             "the way the cavity's opening faces in the file; the die is turned so that it faces up (+z). auto: +z "
             "when the flat faces at the top cover half of the part's outline seen from above, else the extreme whose "
             "flat faces cover the largest share of the outline along their axis",
             member(&P::die, &DieSettings::up)),
      choice("die", "parting", options_of(mesh::partings), die,
             "where the die table meets the part: opening, at its flat face (a part with none is refused); widest, at "
             "its widest section across the up axis, the cavity being the part below (the upper punch forms the "
             "rest); auto: opening when the part has a flat face at an extreme, else widest with the part lying flat "
             "(up: the axis of its largest outline)",
             member(&P::die, &DieSettings::parting)),
      integer("die", "part", {0, 1e6}, die,
              "for a file that holds an assembly (bodies that share no vertex): the body the die is for, numbered by "
              "enclosed volume, largest first; 0: the whole file as one part",
              member(&P::die, &DieSettings::part)),
      // Of the wall roles, the pipeline fills a cavity only.
      choice<mesh::WallRole>("die", "role", {{"cavity", mesh::WallRole::cavity}}, die,
                             "the mesh is the part's shape, open at the die table (its highest z); `diefill sdf --role` takes tools too",
                             member(&P::die, &DieSettings::role)),
      number("die", "voxel_fraction", "largest grain radii", {0.05, 4}, die,
             "SDF voxel edge: contacts are exact either way, finer voxels find them faster near curved walls",
             member(&P::die, &DieSettings::voxel_fraction)),
      number("shoe", "length", "m", {5e-3, metre_range_hi}, settling, "inside, along the motion (x)", member(&P::shoe, &ShoeSettings::length)),
      number("shoe", "width", "m", {5e-3, metre_range_hi}, settling, "inside, across the motion (y)", member(&P::shoe, &ShoeSettings::width)),
      number("shoe", "height", "m", {2e-3, metre_range_hi}, settling, "inside", member(&P::shoe, &ShoeSettings::height)),
      number("shoe", "wall_thickness", "m", {5e-4, 0.05}, settling, "of the box shoe's walls", member(&P::shoe, &ShoeSettings::wall)),
      number("shoe", "fill_height", "m", {1e-3, metre_range_hi}, settling,
             "powder bed in the shoe: three times what the ring takes; outflow does not depend on the head (Beverloo)",
             member(&P::shoe, &ShoeSettings::fill_height)),
      number("shoe", "clearance", "largest grain radii", {0, 10}, settling,
             "gap under the walls; the shoe strikes off at the table: lower pinches grains, higher lets them escape",
             member(&P::shoe, &ShoeSettings::clearance)),
      flag("shoe", "trim_width", settling, "simulate only the shoe's width over the die plus side_margin", member(&P::shoe, &ShoeSettings::trim_width)),
      number("shoe", "side_margin", "m", {0, 0.1}, settling, "kept on each side of the die when trimming", member(&P::shoe, &ShoeSettings::side_margin)),
      text("shoe", "mesh", KeyType::path, settling, "a shoe mesh instead of the box (origin at its inner centre, on the table)",
           member(&P::shoe, &ShoeSettings::mesh)),
      number("motion", "speed", "m/s", {1e-3, 10}, run, "cruise speed of the shoe over the die", member(&P::motion, &MotionSettings::speed)),
      number("motion", "acceleration", "m/s²", {0.1, 1000}, run, "to and from the cruise speed", member(&P::motion, &MotionSettings::acceleration)),
      number("motion", "start_gap", "m", {0, metre_range_hi}, settling,
             "leading wall before the die's edge at the start (where the shoe settles)", member(&P::motion, &MotionSettings::start_gap)),
      number("motion", "end_gap", "m", {0, metre_range_hi}, run, "trailing wall past the die's far edge at a pass's end",
             member(&P::motion, &MotionSettings::end_gap)),
      number("motion", "dwell", "s", {0, 10}, run, "at the far end before returning", member(&P::motion, &MotionSettings::dwell)),
      integer("motion", "passes", {1, 20}, run, "passes over the die", member(&P::motion, &MotionSettings::passes)),
      flag("motion", "return", run, "the shoe comes back after each pass", member(&P::motion, &MotionSettings::return_stroke)),
      number("motion", "shoe_settle_time", "s", zero_or(0.01, 2), settling, "the powder settles in the shoe before it moves (cached)",
             member(&P::motion, &MotionSettings::shoe_settle_time)),
      number("motion", "die_settle_time", "s", zero_or(1e-3, 2), run, "the die settles after the shoe has passed", member(&P::motion, &MotionSettings::die_settle_time)),
      number("powder", "particle_diameter", "m", {1e-6, 5e-3}, settling, "the real powder: a free-flowing atomised metal",
             member(&P::powder, &PowderSettings::particle_diameter)),
      number("powder", "coarse_graining", "", {1, 200}, settling,
             "α: simulated grains α times the real ones; Hertz forces keep bulk behaviour (docs/PHYSICS.md §4)",
             member(&P::powder, &PowderSettings::coarse_graining)),
      number("powder", "diameter_spread", "", {0, 0.5}, settling,
             "relative half-width of the uniform size distribution: ±10 % keeps the packing random", member(&P::powder, &PowderSettings::diameter_spread)),
      integer("powder", "max_grains", {100, 1e8}, settling, "larger α, with a warning, when the shoe would need more",
              member(&P::powder, &PowderSettings::max_grains)),
      text("powder.shape", "mesh", KeyType::path, settling,
           "a grain shape: rigid multi-sphere clumps scaled to the grain diameter (volume-equivalent)", member(&P::powder, &PowderSettings::shape_mesh)),
      number("powder.shape", "tolerance", "", {0.01, 0.5}, settling, "the clump's volume and Hausdorff error",
             member(&P::powder, &PowderSettings::shape_tolerance)),
      choice("powder.shape", "units", options_of(geometry::length_units), settling, "the grain mesh's length unit",
             member(&P::powder, &PowderSettings::shape_units)),
  };
  add_physics_keys<P>(k, spec_of, settling);
  const auto physics_end = std::stable_partition(k.begin(), k.end(), [](const K& key) { return key.table != "simulation"; });
  KeyTable<P> simulation(physics_end, k.end());
  k.erase(physics_end, k.end());
  k.insert(k.end(), simulation.begin(), simulation.end());
  k.push_back(integer("simulation", "seed", {0, 9007199254740991.0}, settling, "of the powder's random packing", member(&P::seed)));
  k.push_back(integer("simulation", "threads", {0, 4096}, nothing, "0: all cores; results do not depend on it", member(&P::threads)));
  k.push_back(number("density", "voxel", "m", zero_or(1e-5, 0.05), run, "0: two grain diameters", member(&P::density, &DensitySettings::voxel)));
  k.push_back(choice("density", "method", options_of(density_methods), run,
                     "exact volume split, or Gaussian coarse graining", member(&P::density, &DensitySettings::method)));
  k.push_back(number("density", "smoothed_width", "m", zero_or(1e-5, 0.05), run,
                     "the smoothed field's Gaussian width and voxel; 0: half a grain diameter", member(&P::density, &DensitySettings::smoothed_width)));
  k.push_back(number("fem", "element_size", "m", zero_or(1e-4, 0.05), run,
                     "the tetrahedra's largest edge in fem/fill.inp; 0: the density voxel", member(&P::fem, &FemSettings::element_size)));
  k.push_back(choice("fem", "elements", options_of(fem_element_kinds), run,
                     "C3D4, C3D10 with a node on every edge, or none: no FEM hand-off", member(&P::fem, &FemSettings::elements)));
  k.push_back(choice("fem", "compaction", options_of(fem_compactions), run,
                     "the worked example: the fill pressed by a punch in CalculiX (fem/compaction.*)", member(&P::fem, &FemSettings::compaction)));
  k.push_back(text("output", "directory", KeyType::text, nothing, "each die writes into DIRECTORY/<die name>/ (relative "
                   "to the working folder)", member(&P::output, &OutputSettings::directory)));
  k.push_back(text("output", "cache", KeyType::text, nothing, "prepared die fields and settled shoes, reused by runs "
                   "that share them; empty: DIRECTORY/.cache", member(&P::output, &OutputSettings::cache)));
  k.push_back(number("output", "snapshot_every", "s", zero_or(1e-3, 10), nothing, "VTU snapshots; 0: the final state only",
                     member(&P::output, &OutputSettings::snapshot_every)));
  k.push_back(number("output", "fill_curve_every", "s", {1e-4, 1}, nothing,
                     "the fill curve's sampling (fill_curve.csv: mass in the cavity against time and the shoe's position)",
                     member(&P::output, &OutputSettings::fill_curve_every)));
  return k;
}

std::vector<dem::Material> default_materials() {
  dem::Material powder;
  powder.name = powder_material_name;
  powder.density = 7800;          // solid steel/iron
  powder.youngs_modulus = 1e7;    // softened from 2e11 Pa: see describe()
  powder.poisson_ratio = 0.3;
  powder.restitution = 0.5;
  powder.sliding_friction = 0.5;
  powder.rolling_friction = 0.1;
  dem::Material steel;
  steel.name = tool_material_name;
  steel.density = 7800;
  steel.youngs_modulus = 2.1e11;
  steel.poisson_ratio = 0.3;
  steel.restitution = 0.5;
  steel.sliding_friction = 0.3;
  steel.rolling_friction = 0.05;
  return {powder, steel};
}

}  // namespace

PipelineScene::PipelineScene() {
  spec.materials = default_materials();
  spec.law.rolling = "epsd";
  spec.max_impact_speed = 1.0;
  spec.stop_overlap = 0.25;
}

const KeyTable<PipelineScene>& pipeline_keys() {
  static const KeyTable<PipelineScene> keys = make_pipeline_keys();
  return keys;
}

int material_named(const dem::ModelSpec& spec, std::string_view name) {
  for (std::size_t m = 0; m < spec.materials.size(); ++m)
    if (spec.materials[m].name == name) return int(m);
  throw diefill::InputError("scene", "materials", "has no material named \"" + std::string(name) + "\"", "Define it");
}

dem::ModelSpec coarse_grained_spec(const dem::ModelSpec& spec, double alpha) {
  dem::ModelSpec scaled = spec;
  scaled.linear_stiffness *= alpha;
  return scaled;
}

PipelineScene load_pipeline_scene(const std::optional<std::filesystem::path>& scene_file,
                                  const std::vector<std::string>& overrides) {
  PipelineScene s;
  TomlDocument doc = scene_file ? TomlDocument::parse(*scene_file) : TomlDocument::parse("(defaults)", std::string());
  if (scene_file) s.source = scene_file->string();
  doc.apply_overrides(overrides);
  Table root = doc.root();
  const std::filesystem::path base = scene_file ? scene_file->parent_path() : std::filesystem::path();
  read_keys(root, pipeline_keys(), s, base);
  const std::vector<std::string> names = read_materials(root, s.spec, base);
  root.finish();

  // What no single range can say, named by the key and, where the scene file gives its table,
  // the file and line.
  const auto refuse = [&](const char* table, const char* key, const std::string& problem, const std::string& remedy) {
    if (std::optional<Table> t = root.table(table)) t->fail(key, problem, remedy);
    throw diefill::InputError(s.source, std::string(table) + "." + key, problem, remedy);
  };
  if (s.shoe.fill_height > s.shoe.height) refuse("shoe", "fill_height", "is higher than the shoe", "Lower it below shoe.height");
  // Each pass starts where the last ended: without a return the shoe walks off the table.
  if (s.motion.passes > 1 && !s.motion.return_stroke)
    refuse("motion", "passes", "more than one pass needs motion.return = true", "Set motion.return = true, or one pass");
  if (!(s.spec.gravity.z() < 0))
    refuse("simulation", "gravity", "must point down (negative z): the powder falls into the die",
           "Give gravity a negative z component, e.g. [0, 0, -9.81]");
  // Powder slides on the polished die table more easily than on itself, unless told otherwise.
  if (s.spec.interactions.empty())
    s.spec.interactions.push_back({int(std::find(names.begin(), names.end(), powder_material_name) - names.begin()),
                                   int(std::find(names.begin(), names.end(), tool_material_name) - names.begin()), std::nullopt, 0.3,
                                   0.05});
  return s;
}

std::string describe(const PipelineScene& s) {
  std::string out = fmt::format("# diefill scene, fully resolved ({}). SI units; the die mesh declares its own.\n", s.source);
  std::vector<std::string_view> tables;
  for (const auto& key : pipeline_keys())
    if (std::find(tables.begin(), tables.end(), key.table) == tables.end()) tables.push_back(key.table);
  for (std::string_view table : tables) {
    const std::string body = describe_table(pipeline_keys(), table, s);
    if (!body.empty()) out += fmt::format("\n[{}]\n{}", table, body);
  }
  return out + "\n" + describe_materials(s.spec);
}

std::string scene_keys_markdown() {
  const PipelineScene defaults;
  return fmt::format(
      "{}\nEach `[[materials]]` entry (defaults: \"powder\" and \"steel\", printed by `diefill scene`; an entry with one of "
      "their names changes only the keys it gives, any other name adds a material):\n\n{}\n"
      "Each `[[interactions]]` entry names two materials (`materials = [\"a\", \"b\"]`) and replaces their mixing rule "
      "(geometric means) for the values it gives:\n\n{}",
      markdown_table(pipeline_keys(), defaults), markdown_table(material_keys(), defaults.spec.materials.front(), "materials[]."),
      markdown_table(interaction_keys(), InteractionEntry{}, "interactions[]."));
}

}  // namespace scene
