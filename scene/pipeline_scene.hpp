#pragma once
// The die-filling scene of `diefill run` and `diefill scene`: embedded defaults that reproduce the
// seed study's setup (J. Mech. Phys. Solids 57 (2009) 10-31): a box shoe 32 mm long (along the
// motion), 50 mm wide and 37 mm high, open at the bottom, sliding on the die table over the
// cavity, filled with a free-flowing metal powder represented by coarse-grained spheres. Every key
// is in pipeline_keys(), with its unit, range and meaning (docs/INTERFACE.md, "Scene keys").
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dem/model.hpp"
#include "mesh/orientation.hpp"
#include "mesh/wall_role.hpp"
#include "scene/choices.hpp"
#include "scene/scene_keys.hpp"

namespace scene {

// The scene compiled: each table of the file read once into the typed settings of the stage that
// reads it (choices as the enums of the module that acts on them), so that a stage receives its
// own settings and not the whole scene.

// [die] the die's mesh and how to read it (the mesh stage)
struct DieSettings {
  std::filesystem::path file;                 // the mesh
  std::optional<geometry::LengthUnit> units;  // unset: guessed from the mesh's size
  mesh::WallRole role = mesh::WallRole::cavity;
  std::optional<mesh::Up> up;                 // unset: found (mesh::find_opening)
  mesh::Parting parting = mesh::Parting::automatic;
  int part = 0;                               // the body of an assembly's file (mesh::DieFile::part); 0: the whole file
  double voxel_fraction = 0.25;               // SDF voxel edge [largest grain radii] (as mesh::default_voxel_fraction)
};

// [shoe] the feeding shoe and the powder in it (metres)
struct ShoeSettings {
  double length = 32e-3, width = 50e-3, height = 37e-3, wall = 3e-3;
  double fill_height = 8e-3;  // powder height in the shoe
  double clearance = 1.0;     // gap between the shoe's walls and the die table [largest grain radii]
  bool trim_width = true;     // simulate only the width over the die plus `side_margin`
  double side_margin = 4e-3;
  std::string mesh;           // optional: a mesh for the shoe instead of the box
};

// [motion] the shoe's strokes and the settling times
struct MotionSettings {
  double speed = 0.1, acceleration = 2.0, start_gap = 2e-3, end_gap = 2e-3, dwell = 0.0;
  int passes = 1;
  bool return_stroke = false;
  double shoe_settle_time = 0.08, die_settle_time = 0.05;
};

// [powder] the real powder and its coarse graining
struct PowderSettings {
  double particle_diameter = 0.1e-3;  // real powder [m]
  double coarse_graining = 8.0;       // α: simulated diameter = α × particle_diameter
  double diameter_spread = 0.1;       // relative half-width of the uniform size distribution
  std::size_t max_grains = 60000;     // coarser grains (larger α) beyond this, with a warning
  std::string shape_mesh;             // clumps (issue 6): a grain surface mesh
  double shape_tolerance = 0.05;
  geometry::LengthUnit shape_units = geometry::LengthUnit::mm;
  double grain_diameter() const { return coarse_graining * particle_diameter; }
};

// [density] the density field binned from the grains (postprocess/density.hpp)
struct DensitySettings {
  double voxel = 0;           // [m]; 0: two grain diameters
  DensityMethod method = DensityMethod::exact;
  double smoothed_width = 0;  // [m]; 0: half a grain diameter
};

// [fem] the hand-off to compaction FEM (docs/INTERFACE.md, "FEM hand-off")
struct FemSettings {
  double element_size = 0;  // [m]; 0: the density voxel
  FemElements elements = FemElements::linear;
  FemCompaction compaction = FemCompaction::calculix;
};

// [output]
struct OutputSettings {
  std::filesystem::path directory = "out";
  std::filesystem::path cache;    // empty: directory / ".cache"
  double snapshot_every = 0;      // [s]; 0: final snapshot only
  double fill_curve_every = 0.002;  // [s]
};

struct PipelineScene {
  std::string source = "(defaults)";  // the scene file, or the defaults
  DieSettings die;
  ShoeSettings shoe;
  MotionSettings motion;
  PowderSettings powder;
  DensitySettings density;
  FemSettings fem;
  OutputSettings output;
  // [materials], [contact], [simulation]
  dem::ModelSpec spec;                // materials "powder", "steel"; laws; gravity; time step
  std::uint64_t seed = 1;
  int threads = 0;
  bool force = false;                 // `--force`: run a size over the limit (pipeline/preflight.hpp); no key
  std::int64_t max_steps = 0;         // a smoke run: every DEM stage ends after this many steps (the scene fuzz test); no key
  bool pictures = true;               // false: no PNGs (smoke runs, the studies' scratch runs nobody looks at); no key

  PipelineScene();  // the defaults: materials "powder" and "steel", EPSD rolling, ...
};

// Every key of the pipeline's scene but the [[materials]] and [[interactions]] entries
// (physics_keys.hpp), in the order `diefill scene` prints them.
const KeyTable<PipelineScene>& pipeline_keys();

// Defaults, then the scene file (when TARGET is a .toml) and `--set` overrides; unknown keys, wrong
// types and values out of their range are errors naming the key, with file and line.
PipelineScene load_pipeline_scene(const std::optional<std::filesystem::path>& scene_file,
                                  const std::vector<std::string>& overrides);
// The pipeline's materials by role, named once: the powder's grains, and the steel of the die, the
// shoe and the table. A scene changes them through [[materials]] entries of these names.
inline constexpr std::string_view powder_material_name = "powder", tool_material_name = "steel";
// Index of the material `name`; InputError when the scene lacks it.
int material_named(const dem::ModelSpec& spec, std::string_view name);
inline int powder_material(const dem::ModelSpec& spec) { return material_named(spec, powder_material_name); }
inline int tool_material(const dem::ModelSpec& spec) { return material_named(spec, tool_material_name); }
// The contact laws for grains `alpha` times the real powder's size (docs/PHYSICS.md §4). Hertz,
// damping to a restitution, rolling and SJKR cohesion scale by themselves; a linear spring must
// stiffen as α, since contact.linear_stiffness is given for the real powder.
dem::ModelSpec coarse_grained_spec(const dem::ModelSpec& spec, double alpha);
// The fully resolved scene as TOML, every key with its value, unit and meaning.
std::string describe(const PipelineScene& scene);
// The Markdown reference of every key (docs/INTERFACE.md, "Scene keys", is generated from it).
std::string scene_keys_markdown();

}  // namespace scene
