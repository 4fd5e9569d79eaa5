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

K number(std::string_view table, std::string_view name, std::string_view unit, ValueRange range, Shapes shapes,
         std::string_view meaning, double P::*member) {
  return {table, name, KeyType::number, unit, range, {}, shapes, meaning,
          [member](const P& s) -> KeyValue { return s.*member; },
          [member](P& s, const KeyValue& v) { s.*member = std::get<double>(v); }};
}

template <class Integer>
K integer(std::string_view table, std::string_view name, ValueRange range, Shapes shapes, std::string_view meaning,
          Integer P::*member) {
  return {table, name, KeyType::integer, "", range, {}, shapes, meaning,
          [member](const P& s) -> KeyValue { return double(s.*member); },
          [member](P& s, const KeyValue& v) { s.*member = Integer(std::get<double>(v)); }};
}

K flag(std::string_view table, std::string_view name, Shapes shapes, std::string_view meaning, bool P::*member) {
  return {table, name, KeyType::boolean, "", {}, {}, shapes, meaning,
          [member](const P& s) -> KeyValue { return s.*member; },
          [member](P& s, const KeyValue& v) { s.*member = std::get<bool>(v); }};
}

template <class Text>
K text(std::string_view table, std::string_view name, KeyType type, std::vector<std::string_view> choices, Shapes shapes,
       std::string_view meaning, Text P::*member) {
  return {table, name, type, "", {}, std::move(choices), shapes, meaning,
          [member](const P& s) -> KeyValue { return std::filesystem::path(s.*member).string(); },
          [member](P& s, const KeyValue& v) { s.*member = Text(std::get<std::string>(v)); }};
}

dem::ModelSpec& spec_of(P& s) { return s.spec; }

constexpr double metre_range_hi = 1.0;  // the die table is a desk, not a quarry

KeyTable<P> make_pipeline_keys() {
  const Shapes die = Shapes::die, settling = Shapes::settling, run = Shapes::run, nothing = Shapes::nothing;
  KeyTable<P> k = {
      text("die", "file", KeyType::path, {}, die, "the die's cavity mesh (relative to the scene file)", &P::die),
      text("die", "units", KeyType::choice, {"auto", "mm", "m", "in"}, die,
           "the mesh file's length unit (files store none); auto: guessed from its size, 3 or more across mm, 1 to 3 "
           "inches, under 1 metres (a warning says so unless mm)",
           &P::die_units),
      text("die", "up", KeyType::choice, {"auto", "+z", "-z", "+x", "-x", "+y", "-y"}, die,
           "the way the cavity's opening faces in the file; the die is turned so that it faces up (+z). auto: +z "
           "when the flat faces at the top cover half of the part's outline seen from above, else the extreme whose "
           "flat faces cover the largest share of the outline along their axis",
           &P::die_up),
      text("die", "parting", KeyType::choice, {"auto", "opening", "widest"}, die,
           "where the die table meets the part: opening, at its flat face (a part with none is refused); widest, at "
           "its widest section across the up axis, the cavity being the part below (the upper punch forms the "
           "rest); auto: opening when the part has a flat face at an extreme, else widest with the part lying flat "
           "(up: the axis of its largest outline)",
           &P::die_parting),
      integer("die", "part", {0, 1e6}, die,
              "for a file that holds an assembly (bodies that share no vertex): the body the die is for, numbered by "
              "enclosed volume, largest first; 0: the whole file as one part",
              &P::die_part),
      text("die", "role", KeyType::choice, {"cavity"}, die,
           "the mesh is the part's shape, open at the die table (its highest z); `diefill sdf --role` takes tools too",
           &P::die_role),
      number("die", "voxel_fraction", "largest grain radii", {0.05, 4}, die,
             "SDF voxel edge: contacts are exact either way, finer voxels find them faster near curved walls",
             &P::die_voxel_fraction),
      number("shoe", "length", "m", {5e-3, metre_range_hi}, settling, "inside, along the motion (x)", &P::shoe_length),
      number("shoe", "width", "m", {5e-3, metre_range_hi}, settling, "inside, across the motion (y)", &P::shoe_width),
      number("shoe", "height", "m", {2e-3, metre_range_hi}, settling, "inside", &P::shoe_height),
      number("shoe", "wall_thickness", "m", {5e-4, 0.05}, settling, "of the box shoe's walls", &P::shoe_wall),
      number("shoe", "fill_height", "m", {1e-3, metre_range_hi}, settling,
             "powder bed in the shoe: three times what the ring takes; outflow does not depend on the head (Beverloo)",
             &P::fill_height),
      number("shoe", "clearance", "largest grain radii", {0, 10}, settling,
             "gap under the walls; the shoe strikes off at the table: lower pinches grains, higher lets them escape",
             &P::clearance),
      flag("shoe", "trim_width", settling, "simulate only the shoe's width over the die plus side_margin", &P::trim_width),
      number("shoe", "side_margin", "m", {0, 0.1}, settling, "kept on each side of the die when trimming", &P::side_margin),
      text("shoe", "mesh", KeyType::path, {}, settling, "a shoe mesh instead of the box (origin at its inner centre, on the table)",
           &P::shoe_mesh),
      number("motion", "speed", "m/s", {1e-3, 10}, run, "cruise speed of the shoe over the die", &P::speed),
      number("motion", "acceleration", "m/s²", {0.1, 1000}, run, "to and from the cruise speed", &P::acceleration),
      number("motion", "start_gap", "m", {0, metre_range_hi}, settling,
             "leading wall before the die's edge at the start (where the shoe settles)", &P::start_gap),
      number("motion", "end_gap", "m", {0, metre_range_hi}, run, "trailing wall past the die's far edge at a pass's end",
             &P::end_gap),
      number("motion", "dwell", "s", {0, 10}, run, "at the far end before returning", &P::dwell),
      integer("motion", "passes", {1, 20}, run, "passes over the die", &P::passes),
      flag("motion", "return", run, "the shoe comes back after each pass", &P::return_stroke),
      number("motion", "shoe_settle_time", "s", zero_or(0.01, 2), settling, "the powder settles in the shoe before it moves (cached)",
             &P::shoe_settle_time),
      number("motion", "die_settle_time", "s", zero_or(1e-3, 2), run, "the die settles after the shoe has passed", &P::die_settle_time),
      number("powder", "particle_diameter", "m", {1e-6, 5e-3}, settling, "the real powder: a free-flowing atomised metal",
             &P::particle_diameter),
      number("powder", "coarse_graining", "", {1, 200}, settling,
             "α: simulated grains α times the real ones; Hertz forces keep bulk behaviour (docs/PHYSICS.md §4)",
             &P::coarse_graining),
      number("powder", "diameter_spread", "", {0, 0.5}, settling,
             "relative half-width of the uniform size distribution: ±10 % keeps the packing random", &P::diameter_spread),
      integer("powder", "max_grains", {100, 1e8}, settling, "larger α, with a warning, when the shoe would need more",
              &P::max_grains),
      text("powder.shape", "mesh", KeyType::path, {}, settling,
           "a grain shape: rigid multi-sphere clumps scaled to the grain diameter (volume-equivalent)", &P::shape_mesh),
      number("powder.shape", "tolerance", "", {0.01, 0.5}, settling, "the clump's volume and Hausdorff error",
             &P::shape_tolerance),
      text("powder.shape", "units", KeyType::choice, {"mm", "m", "in"}, settling, "the grain mesh's length unit",
           &P::shape_units),
  };
  add_physics_keys<P>(k, spec_of, settling);
  const auto physics_end = std::stable_partition(k.begin(), k.end(), [](const K& key) { return key.table != "simulation"; });
  KeyTable<P> simulation(physics_end, k.end());
  k.erase(physics_end, k.end());
  k.insert(k.end(), simulation.begin(), simulation.end());
  k.push_back(integer("simulation", "seed", {0, 9007199254740991.0}, settling, "of the powder's random packing", &P::seed));
  k.push_back(integer("simulation", "threads", {0, 4096}, nothing, "0: all cores; results do not depend on it", &P::threads));
  k.push_back(number("density", "voxel", "m", zero_or(1e-5, 0.05), run, "0: two grain diameters", &P::density_voxel));
  k.push_back(text("density", "method", KeyType::choice, {"exact", "gaussian"}, run,
                   "exact volume split, or Gaussian coarse graining", &P::density_method));
  k.push_back(number("density", "smoothed_width", "m", zero_or(1e-5, 0.05), run,
                     "the smoothed field's Gaussian width and voxel; 0: half a grain diameter", &P::density_smoothed_width));
  k.push_back(number("fem", "element_size", "m", zero_or(1e-4, 0.05), run,
                     "the tetrahedra's largest edge in fem/fill.inp; 0: the density voxel", &P::fem_element_size));
  k.push_back(text("fem", "elements", KeyType::choice, {"linear", "quadratic", "none"}, run,
                   "C3D4, C3D10 with a node on every edge, or none: no FEM hand-off", &P::fem_elements));
  k.push_back(text("fem", "compaction", KeyType::choice, {"calculix", "none"}, run,
                   "the worked example: the fill pressed by a punch in CalculiX (fem/compaction.*)", &P::fem_compaction));
  k.push_back(text("output", "directory", KeyType::text, {}, nothing, "each die writes into DIRECTORY/<die name>/ (relative "
                   "to the working folder)", &P::out));
  k.push_back(text("output", "cache", KeyType::text, {}, nothing, "prepared die fields and settled shoes, reused by runs "
                   "that share them; empty: DIRECTORY/.cache", &P::cache));
  k.push_back(number("output", "snapshot_every", "s", zero_or(1e-3, 10), nothing, "VTU snapshots; 0: the final state only",
                     &P::snapshot_every));
  k.push_back(number("output", "fill_curve_every", "s", {1e-4, 1}, nothing,
                     "the fill curve's sampling (fill_curve.csv: mass in the cavity against time and the shoe's position)",
                     &P::fill_curve_every));
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
  if (s.fill_height > s.shoe_height) refuse("shoe", "fill_height", "is higher than the shoe", "Lower it below shoe.height");
  // Each pass starts where the last ended: without a return the shoe walks off the table.
  if (s.passes > 1 && !s.return_stroke)
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
