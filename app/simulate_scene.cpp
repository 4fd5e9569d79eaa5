#include "app/simulate_scene.hpp"

#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>

#include "core/error.hpp"
#include "dem/io.hpp"
#include "mesh/die.hpp"

namespace app {

namespace fs = std::filesystem;

int material_index(const std::vector<std::string>& names, const std::string& name, Table& where, const std::string& key) {
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end())
    where.fail(key, "names material '" + name + "', which is not defined", "Define it in a [[materials]] table");
  return int(it - names.begin());
}

std::vector<std::string> read_materials_and_contact(Table& root, dem::ModelSpec& spec) {
  if (auto contact = root.table("contact")) {
    auto choose = [&](const std::string& key, std::vector<std::string> allowed) -> int {
      const auto value = contact->string(key);
      if (!value) return -1;
      const auto it = std::find(allowed.begin(), allowed.end(), *value);
      if (it == allowed.end())
        contact->fail(key, "'" + *value + "' is not a known law", "Use one of: " + fmt::format("{}", fmt::join(allowed, ", ")));
      return int(it - allowed.begin());
    };
    if (int n = choose("normal", {"hertz", "linear"}); n >= 0) spec.normal = dem::NormalLaw(n);
    if (int t = choose("tangential", {"mindlin", "none"}); t >= 0) spec.tangential = dem::TangentialLaw(t);
    if (int r = choose("rolling", {"epsd", "cdt", "none"}); r >= 0) spec.rolling = dem::RollingLaw(r);
    if (int c = choose("cohesion", {"sjkr", "none"}); c >= 0) spec.cohesion = dem::CohesionLaw(c);
    spec.linear_stiffness = contact->number("linear_stiffness", spec.linear_stiffness);
    contact->finish();
  }
  std::vector<std::string> names;
  auto materials = root.tables("materials");
  if (!materials.empty()) spec.materials.clear();
  for (Table& t : materials) {
    dem::Material m;
    m.name = t.string("name").value_or(fmt::format("material{}", names.size()));
    m.density = t.number("density", m.density);
    m.youngs_modulus = t.number("youngs_modulus", m.youngs_modulus);
    m.poisson_ratio = t.number("poisson_ratio", m.poisson_ratio);
    m.restitution = t.number("restitution", m.restitution);
    m.sliding_friction = t.number("sliding_friction", m.sliding_friction);
    m.rolling_friction = t.number("rolling_friction", m.rolling_friction);
    m.cohesion_energy_density = t.number("cohesion_energy_density", m.cohesion_energy_density);
    t.finish();
    names.push_back(m.name);
    spec.materials.push_back(m);
  }
  if (materials.empty())
    for (const dem::Material& m : spec.materials) names.push_back(m.name);
  for (Table& t : root.tables("interactions")) {
    const auto pair = t.strings("materials");
    if (!pair || pair->size() != 2) t.fail("materials", "must name two materials", "Write materials = [\"a\", \"b\"]");
    dem::Interaction it;
    it.a = material_index(names, (*pair)[0], t, "materials");
    it.b = material_index(names, (*pair)[1], t, "materials");
    it.restitution = t.number("restitution");
    it.sliding_friction = t.number("sliding_friction");
    it.rolling_friction = t.number("rolling_friction");
    t.finish();
    spec.interactions.push_back(it);
  }
  return names;
}

dem::Motion read_motion(Table& t) {
  dem::Motion m;
  if (auto v = t.vec3("velocity")) m.start_velocity = *v;
  if (auto v = t.vec3("start_velocity")) m.start_velocity = *v;
  if (auto p = t.vec3("start_position")) m.start_position = *p;
  if (auto w = t.vec3("angular_velocity")) m.angular_velocity = *w;
  if (auto p = t.vec3("pivot")) m.pivot = *p;
  for (Table& s : t.tables("segments")) {
    dem::Motion::Segment seg;
    const auto duration = s.number("duration");
    if (!duration || !(*duration > 0)) s.fail("duration", "must be a positive time [s]", "Give the segment's duration");
    seg.duration = *duration;
    seg.acceleration = s.vec3("acceleration").value_or(dem::Vec3::Zero());
    s.finish();
    m.segments.push_back(seg);
  }
  t.finish();
  return m;
}

SimulationScene load_simulation_scene(const fs::path& path, const std::vector<std::string>& overrides) {
  TomlDocument doc = TomlDocument::parse(path);
  doc.apply_overrides(overrides);
  Table root = doc.root();
  SimulationScene scene;
  scene.source = path.string();
  const fs::path base = path.parent_path();
  dem::ModelSpec& spec = scene.spec;
  spec.materials = {dem::Material{}};
  spec.materials[0].name = "default";

  if (auto sim = root.table("simulation")) {
    scene.duration = sim->number("duration", scene.duration);
    if (!(scene.duration > 0)) sim->fail("duration", "must be positive [s]", "Give the simulated time in seconds");
    bool automatic = false;
    if (auto dt = sim->number_or("time_step", "auto", automatic)) spec.time_step = *dt;
    spec.time_step_fraction = sim->number("time_step_fraction", spec.time_step_fraction);
    spec.max_impact_speed = sim->number("max_impact_speed", spec.max_impact_speed);
    if (auto skin = sim->number("skin")) spec.skin = *skin;
    if (auto g = sim->vec3("gravity")) spec.gravity = *g;
    if (auto seed = sim->integer("seed")) scene.seed = std::uint64_t(*seed);
    if (auto threads = sim->integer("threads")) scene.threads = int(*threads);
    spec.stop_overlap = sim->number("stop_overlap", spec.stop_overlap);
    sim->finish();
  }
  const std::vector<std::string> names = read_materials_and_contact(root, spec);

  auto particles = root.table("particles");
  if (!particles) root.fail("particles", "is missing", "Add [particles] with file = \"particles.csv\"");
  const auto file = particles->string("file");
  if (!file) particles->fail("file", "is missing", "Name the particles CSV");
  const int material = material_index(names, particles->string("material").value_or(names.front()), *particles, "material");
  particles->finish();
  scene.state = dem::read_particles_csv(base / *file, material, spec.materials[std::size_t(material)].density);

  // The domain defaults to the particles' box, generously enlarged.
  dem::Vec3 lo = scene.state.x.front(), hi = lo;
  double r_max = 0;
  for (std::size_t i = 0; i < scene.state.size(); ++i) {
    lo = lo.cwiseMin(scene.state.x[i]);
    hi = hi.cwiseMax(scene.state.x[i]);
    r_max = std::max(r_max, scene.state.radius[i]);
  }
  const dem::Vec3 margin = dem::Vec3::Constant(std::max(0.5 * (hi - lo).maxCoeff(), 20 * r_max));
  spec.domain = {lo - margin, hi + margin};
  if (auto domain = root.table("domain")) {
    if (auto v = domain->vec3("lo")) spec.domain.lo = *v;
    if (auto v = domain->vec3("hi")) spec.domain.hi = *v;
    domain->finish();
  }

  for (Table& w : root.tables("walls")) {
    const std::string type = w.string("type").value_or("plane");
    const int wall_material = material_index(names, w.string("material").value_or(names.front()), w, "material");
    if (type == "plane") {
      dem::PlaneWall plane;
      plane.point = w.vec3("point").value_or(dem::Vec3::Zero());
      plane.normal = w.vec3("normal").value_or(dem::Vec3::UnitZ());
      if (plane.normal.norm() == 0) w.fail("normal", "must not be zero", "Give the direction towards the particles");
      plane.material = wall_material;
      plane.name = w.path();
      spec.planes.push_back(plane);
    } else if (type == "mesh") {
      const auto mesh_file = w.string("file");
      if (!mesh_file) w.fail("file", "is missing", "Name the wall's mesh");
      const std::optional<double> skin = spec.skin;
      mesh::DieOptions options = mesh::die_options_for_grains(r_max, skin.value_or(0.5 * r_max));
      options.unit = mesh::parse_unit(w.string("units").value_or("mm"), w.path() + ".units");
      options.role = mesh::parse_role(w.string("role").value_or("cavity"), w.path() + ".role");
      const mesh::PreparedDie die = mesh::prepare_die(base / *mesh_file, options, std::nullopt);
      dem::MeshWall wall;
      wall.field = std::make_shared<const mesh::WallField>(die.sdf.wall_field(die.solid));
      wall.material = wall_material;
      wall.name = w.path();
      if (auto motion = w.table("motion")) wall.motion = read_motion(*motion);
      spec.meshes.push_back(wall);
    } else {
      w.fail("type", "'" + type + "' is not a wall type", "Use plane or mesh");
    }
    w.finish();
  }

  if (auto out = root.table("output")) {
    if (auto dir = out->string("directory")) scene.output.directory = *dir;
    scene.output.trajectory = out->boolean("trajectory").value_or(scene.output.trajectory);
    scene.output.trajectory_every = out->number("trajectory_every", scene.output.trajectory_every);
    scene.output.snapshot_every = out->number("snapshot_every", scene.output.snapshot_every);
    out->finish();
  }
  root.finish();
  return scene;
}

}  // namespace app
