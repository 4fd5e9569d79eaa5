#include "app/pipeline_scene.hpp"

#include <fmt/core.h>

#include "app/simulate_scene.hpp"
#include "app/toml_reader.hpp"
#include "core/error.hpp"

#include <algorithm>

namespace app {

namespace {

std::vector<dem::Material> default_materials() {
  dem::Material powder;
  powder.name = "powder";
  powder.density = 7800;          // solid steel/iron
  powder.youngs_modulus = 1e7;    // softened from 2e11 Pa: see describe()
  powder.poisson_ratio = 0.3;
  powder.restitution = 0.5;
  powder.sliding_friction = 0.5;
  powder.rolling_friction = 0.1;
  dem::Material steel;
  steel.name = "steel";
  steel.density = 7800;
  steel.youngs_modulus = 2.1e11;
  steel.poisson_ratio = 0.3;
  steel.restitution = 0.5;
  steel.sliding_friction = 0.3;
  steel.rolling_friction = 0.05;
  return {powder, steel};
}

}  // namespace

int material_named(const dem::ModelSpec& spec, const std::string& name) {
  for (std::size_t m = 0; m < spec.materials.size(); ++m)
    if (spec.materials[m].name == name) return int(m);
  throw diefill::InputError("scene", "materials", "has no material named \"" + name + "\"", "Define it");
}

dem::ModelSpec coarse_grained_spec(const dem::ModelSpec& spec, double alpha) {
  dem::ModelSpec scaled = spec;
  scaled.linear_stiffness *= alpha;
  return scaled;
}

PipelineScene load_pipeline_scene(const std::optional<std::filesystem::path>& scene_file,
                                  const std::vector<std::string>& overrides) {
  PipelineScene s;
  s.spec.materials = default_materials();
  s.spec.rolling = dem::RollingLaw::epsd;
  s.spec.max_impact_speed = 1.0;
  s.spec.stop_overlap = 0.25;
  TomlDocument doc = scene_file ? TomlDocument::parse(*scene_file) : TomlDocument::parse("(defaults)", std::string());
  if (scene_file) s.source = scene_file->string();
  doc.apply_overrides(overrides);
  Table root = doc.root();
  const std::filesystem::path base = scene_file ? scene_file->parent_path() : std::filesystem::path();

  if (auto t = root.table("die")) {
    if (auto f = t->string("file")) s.die = base / *f;
    s.die_units = t->string("units").value_or(s.die_units);
    s.die_role = t->string("role").value_or(s.die_role);
    s.die_voxel_fraction = t->number("voxel_fraction", s.die_voxel_fraction);
    if (!(s.die_voxel_fraction > 0) || s.die_voxel_fraction > 4)
      t->fail("voxel_fraction", "must lie in (0, 4] [largest grain radii]",
              "Coarser voxels let grains through thin features; 0.25 is the default");
    t->finish();
  }
  if (auto t = root.table("shoe")) {
    s.shoe_length = t->number("length", s.shoe_length);
    s.shoe_width = t->number("width", s.shoe_width);
    s.shoe_height = t->number("height", s.shoe_height);
    s.shoe_wall = t->number("wall_thickness", s.shoe_wall);
    s.fill_height = t->number("fill_height", s.fill_height);
    s.clearance = t->number("clearance", s.clearance);
    if (s.clearance < 0) t->fail("clearance", "must not be negative [largest grain radii]", "Give the gap under the shoe's walls");
    s.trim_width = t->boolean("trim_width").value_or(s.trim_width);
    s.side_margin = t->number("side_margin", s.side_margin);
    if (auto m = t->string("mesh")) s.shoe_mesh = (base / *m).string();
    for (const char* key : {"length", "width", "height", "wall_thickness", "fill_height", "side_margin"})
      if (t->has(key) && !(*t->number(key) > 0)) t->fail(key, "must be positive [m]", "Give a length in metres");
    if (s.fill_height > s.shoe_height) t->fail("fill_height", "is higher than the shoe", "Lower it below shoe.height");
    t->finish();
  }
  if (auto t = root.table("motion")) {
    s.speed = t->number("speed", s.speed);
    s.acceleration = t->number("acceleration", s.acceleration);
    s.start_gap = t->number("start_gap", s.start_gap);
    s.end_gap = t->number("end_gap", s.end_gap);
    s.dwell = t->number("dwell", s.dwell);
    if (auto p = t->integer("passes")) s.passes = int(*p);
    s.return_stroke = t->boolean("return").value_or(s.return_stroke);
    s.shoe_settle_time = t->number("shoe_settle_time", s.shoe_settle_time);
    s.die_settle_time = t->number("die_settle_time", s.die_settle_time);
    if (!(s.speed > 0)) t->fail("speed", "must be positive [m/s]", "Give the shoe's speed");
    if (!(s.acceleration > 0)) t->fail("acceleration", "must be positive [m/s²]", "Give the shoe's acceleration");
    if (s.passes < 1) t->fail("passes", "must be at least 1", "Give the number of passes over the die");
    t->finish();
  }
  if (auto t = root.table("powder")) {
    s.particle_diameter = t->number("particle_diameter", s.particle_diameter);
    s.coarse_graining = t->number("coarse_graining", s.coarse_graining);
    s.diameter_spread = t->number("diameter_spread", s.diameter_spread);
    if (auto m = t->integer("max_grains")) s.max_grains = std::size_t(std::max<std::int64_t>(1, *m));
    if (auto shape = t->table("shape")) {
      if (auto m = shape->string("mesh")) s.shape_mesh = (base / *m).string();
      s.shape_tolerance = shape->number("tolerance", s.shape_tolerance);
      if (auto u = shape->string("units")) s.shape_units = *u;
      shape->finish();
    }
    if (!(s.particle_diameter > 0)) t->fail("particle_diameter", "must be positive [m]", "Give the powder's diameter");
    if (!(s.coarse_graining >= 1)) t->fail("coarse_graining", "must be at least 1", "1 simulates the real grain size");
    if (s.diameter_spread < 0 || s.diameter_spread >= 1) t->fail("diameter_spread", "must lie in [0, 1)", "Give a relative spread");
    t->finish();
  }
  const std::vector<std::string> names = read_materials_and_contact(root, s.spec);
  for (const char* needed : {"powder", "steel"})
    if (std::find(names.begin(), names.end(), needed) == names.end())
      root.fail("materials", std::string("must define a material named \"") + needed + "\"",
                "The powder is \"powder\"; the die and shoe are \"steel\"");
  // Powder slides on the polished die table more easily than on itself, unless told otherwise.
  if (s.spec.interactions.empty())
    s.spec.interactions.push_back({int(std::find(names.begin(), names.end(), "powder") - names.begin()),
                                   int(std::find(names.begin(), names.end(), "steel") - names.begin()), std::nullopt, 0.3,
                                   0.05});
  if (auto t = root.table("simulation")) {
    bool automatic = false;
    if (auto dt = t->number_or("time_step", "auto", automatic)) s.spec.time_step = *dt;
    s.spec.time_step_fraction = t->number("time_step_fraction", s.spec.time_step_fraction);
    s.spec.max_impact_speed = t->number("max_impact_speed", s.spec.max_impact_speed);
    if (auto g = t->vec3("gravity")) s.spec.gravity = *g;
    if (auto skin = t->number("skin")) s.spec.skin = *skin;
    if (auto seed = t->integer("seed")) s.seed = std::uint64_t(*seed);
    if (auto threads = t->integer("threads")) s.threads = int(*threads);
    s.spec.stop_overlap = t->number("stop_overlap", s.spec.stop_overlap);
    t->finish();
  }
  if (auto t = root.table("density")) {
    s.density_voxel = t->number("voxel", s.density_voxel);
    s.density_method = t->string("method").value_or(s.density_method);
    if (s.density_method != "exact" && s.density_method != "gaussian")
      t->fail("method", "must be \"exact\" or \"gaussian\"", "Choose a binning method");
    t->finish();
  }
  if (auto t = root.table("output")) {
    if (auto d = t->string("directory")) s.out = *d;
    s.snapshot_every = t->number("snapshot_every", s.snapshot_every);
    t->finish();
  }
  root.finish();
  return s;
}

std::string describe(const PipelineScene& s) {
  auto named = [&](const char* name) -> const dem::Material& {
    return *std::find_if(s.spec.materials.begin(), s.spec.materials.end(), [&](const dem::Material& m) { return m.name == name; });
  };
  const dem::Material& p = named("powder");
  const dem::Material& w = named("steel");
  auto law = [](auto value, std::initializer_list<const char*> names) { return *(names.begin() + int(value)); };
  std::string out;
  out += fmt::format("# diefill scene, fully resolved ({}). SI units; the die mesh declares its own.\n\n", s.source);
  out += "[die]\n";
  out += fmt::format("file = \"{}\"\n", s.die.string());
  out += fmt::format("units = \"{}\"\n", s.die_units);
  out += fmt::format("role = \"{}\"            # the mesh is the part's shape, open at the die table (its highest z)\n", s.die_role);
  out += fmt::format("voxel_fraction = {}       # SDF voxel edge in largest grain radii: contacts are exact either way, finer voxels find them faster near curved walls\n\n", s.die_voxel_fraction);
  out += "[shoe]                      # the seed study's box shoe, open at the bottom\n";
  out += fmt::format("length = {}              # [m] inside, along the motion (x)\n", s.shoe_length);
  out += fmt::format("width = {}                # [m] inside, across the motion (y)\n", s.shoe_width);
  out += fmt::format("height = {}\n", s.shoe_height);
  out += fmt::format("wall_thickness = {}\n", s.shoe_wall);
  out += fmt::format("fill_height = {}         # [m] powder in the shoe: three times what the ring takes; outflow does not depend on the head above an opening (Beverloo)\n", s.fill_height);
  out += fmt::format("clearance = {}            # [largest grain radii] gap under the walls; the shoe strikes off at the table (grains centred below pass under): a wall lower than a radius pinches grains, one higher lets them escape\n", s.clearance);
  out += fmt::format("trim_width = {}          # simulate only the shoe's width over the die plus side_margin: powder beyond never reaches the cavity\n", s.trim_width);
  out += fmt::format("side_margin = {}         # [m] kept on each side of the die when trimming\n", s.side_margin);
  if (!s.shoe_mesh.empty()) out += fmt::format("mesh = \"{}\"\n", s.shoe_mesh);
  out += "\n[motion]\n";
  out += fmt::format("speed = {}                 # [m/s] cruise speed of the shoe over the die\n", s.speed);
  out += fmt::format("acceleration = {}          # [m/s²] to and from the cruise speed\n", s.acceleration);
  out += fmt::format("start_gap = {}           # [m] leading wall before the die's edge at the start\n", s.start_gap);
  out += fmt::format("end_gap = {}             # [m] trailing wall past the die's far edge at the end of a pass\n", s.end_gap);
  out += fmt::format("dwell = {}                 # [s] at the far end before returning\n", s.dwell);
  out += fmt::format("passes = {}\n", s.passes);
  out += fmt::format("return = {}             # the shoe comes back after each pass\n", s.return_stroke);
  out += fmt::format("shoe_settle_time = {}     # [s] the powder settles in the shoe before it moves (cached)\n", s.shoe_settle_time);
  out += fmt::format("die_settle_time = {}      # [s] the die settles after the shoe has passed\n\n", s.die_settle_time);
  out += "[powder]\n";
  out += fmt::format("particle_diameter = {}   # [m] the real powder: a free-flowing atomised metal\n", s.particle_diameter);
  out += fmt::format("coarse_graining = {}       # α: grains {} mm across; Hertz forces keep bulk behaviour (PHYSICS.md §4)\n", s.coarse_graining, s.grain_diameter() * 1e3);
  out += fmt::format("diameter_spread = {}       # ±10 % sizes keep the packing random, not crystalline\n", s.diameter_spread);
  out += fmt::format("max_grains = {}         # larger α when the powder would need more grains\n", s.max_grains);
  if (!s.shape_mesh.empty()) out += fmt::format("shape = {{ mesh = \"{}\", tolerance = {}, units = \"{}\" }}  # rigid clumps scaled to the grain diameter (volume-equivalent)\n", s.shape_mesh, s.shape_tolerance, s.shape_units);
  out += "\n[contact]\n";
  out += fmt::format("normal = \"{}\"\n", law(s.spec.normal, {"hertz", "linear"}));
  out += fmt::format("tangential = \"{}\"\n", law(s.spec.tangential, {"mindlin", "none"}));
  out += fmt::format("rolling = \"{}\"            # spheres need rolling resistance for 30-40° repose angles\n", law(s.spec.rolling, {"epsd", "cdt", "none"}));
  out += fmt::format("cohesion = \"{}\"\n", law(s.spec.cohesion, {"sjkr", "none"}));
  out += fmt::format("linear_stiffness = {}      # [N/m] the real powder's, for the linear law; coarse grains get α times it\n\n",
                     s.spec.linear_stiffness);
  auto material = [&](const dem::Material& m, const char* why_e) {
    out += "[[materials]]\n";
    out += fmt::format("name = \"{}\"\n", m.name);
    out += fmt::format("density = {}\n", m.density);
    out += fmt::format("youngs_modulus = {}   {}\n", m.youngs_modulus, why_e);
    out += fmt::format("poisson_ratio = {}\n", m.poisson_ratio);
    out += fmt::format("restitution = {}\n", m.restitution);
    out += fmt::format("sliding_friction = {}\n", m.sliding_friction);
    out += fmt::format("rolling_friction = {}\n", m.rolling_friction);
    out += fmt::format("cohesion_energy_density = {}\n\n", m.cohesion_energy_density);
  };
  material(p, "# softened from 2e11 Pa for a 1000x longer time step; overlaps stay below 1 % of the radius (checked each run)");
  material(w, "# the die and the shoe: steel");
  for (const dem::Material& m : s.spec.materials)
    if (m.name != "powder" && m.name != "steel") material(m, "");
  for (const dem::Interaction& it : s.spec.interactions) {
    out += "[[interactions]]\n";
    out += fmt::format("materials = [\"{}\", \"{}\"]\n", s.spec.materials[std::size_t(it.a)].name, s.spec.materials[std::size_t(it.b)].name);
    if (it.restitution) out += fmt::format("restitution = {}\n", *it.restitution);
    if (it.sliding_friction) out += fmt::format("sliding_friction = {}   # powder on a polished die table\n", *it.sliding_friction);
    if (it.rolling_friction) out += fmt::format("rolling_friction = {}\n", *it.rolling_friction);
    out += "\n";
  }
  out += "[simulation]\n";
  out += s.spec.time_step ? fmt::format("time_step = {}\n", *s.spec.time_step)
                          : "time_step = \"auto\"         # a fraction of the Rayleigh and Hertz collision times\n";
  out += fmt::format("time_step_fraction = {}\n", s.spec.time_step_fraction);
  out += fmt::format("max_impact_speed = {}       # [m/s] for the collision time; raised to sqrt(2 g depth) + shoe speed for deeper dies\n", s.spec.max_impact_speed);
  out += fmt::format("gravity = [{}, {}, {}]\n", s.spec.gravity.x(), s.spec.gravity.y(), s.spec.gravity.z());
  if (s.spec.skin) out += fmt::format("skin = {}\n", *s.spec.skin);
  out += fmt::format("seed = {}\n", s.seed);
  out += fmt::format("threads = {}                # 0: all cores; results do not depend on it\n", s.threads);
  out += fmt::format("stop_overlap = {}          # stop (exit status 3) when an overlap exceeds this fraction of a radius: flowing grains overlap 1-2 %, the shoe's cut keeps a grain it pinches under half this, a time step past the stable limit goes far beyond\n\n", s.spec.stop_overlap);
  out += "[density]\n";
  out += fmt::format("voxel = {}                  # [m]; 0: two grain diameters\n", s.density_voxel);
  out += fmt::format("method = \"{}\"             # exact volume split, or \"gaussian\" coarse graining\n\n", s.density_method);
  out += "[output]\n";
  out += fmt::format("directory = \"{}\"\n", s.out.string());
  out += fmt::format("snapshot_every = {}         # [s] VTU snapshots; 0: the final state only\n", s.snapshot_every);
  return out;
}

}  // namespace app
