#pragma once
// The simulation's Model (immutable while stepping) and the spec it is compiled from, after
// MuJoCo's mjModel/mjData split: every stage is `void stage(const Model&, State&)`.
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "dem/contact.hpp"
#include "dem/contact_laws.hpp"
#include "dem/motion.hpp"
#include "dem/types.hpp"
#include "geometry/wall_field.hpp"

namespace dem {

struct Material {
  std::string name;
  double density = 2500;            // [kg/m³]
  double youngs_modulus = 5e6;      // [Pa]
  double poisson_ratio = 0.3;
  double restitution = 0.5;
  double sliding_friction = 0.5;
  double rolling_friction = 0.0;    // dimensionless
  double cohesion_energy_density = 0.0;  // [J/m³] (SJKR)
};

// Overrides the mixing rule for one pair of materials.
struct Interaction {
  int a = 0, b = 0;
  std::optional<double> restitution, sliding_friction, rolling_friction;
};

struct PlaneWall {
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();  // unit, towards the particles
  int material = 0;
  std::string name = "plane";
};

// A rigid wall given by a distance field in its own frame, placed by its motion.
struct MeshWall {
  std::shared_ptr<const geometry::WallField> field;
  int material = 0;
  Motion motion;
  std::string name = "mesh";
  // The cut: grains whose centre lies less than cut_fraction of their radius above cut_z pass
  // under the wall untouched, and the others overlap it no deeper than their centre's height
  // above that level. A feed shoe cuts the fill at the die table, and a coarse grain stands for
  // a lump of powder that the cut assigns by its centre. Without the cut a rigid shoe pinches
  // any grain straddling the cavity's rim against the far cavity wall, where it can neither
  // rise nor sink; with it, a grain pinched between the table and the wall overlaps the two by
  // at most (1 - cut_fraction) of its radius together. A grain of the bottom layer (its centre
  // less than a radius above that level) overlaps the wall no deeper than cut_cap of its radius,
  // the cap rising with the height beyond: one pinched there on a grain at the rim (its centre
  // up to a third of a radius above the cut) would otherwise drive that pair past the stop limit
  // (issue 44: 2 of 3 soft-powder runs at 0.5 m/s stopped at the strike-off, 1 of 3 at half the
  // time step), and a softened powder presses the pair about twice as deep as the wall.
  double cut_z = -std::numeric_limits<double>::infinity();
  double cut_fraction = 0;
  double cut_cap = std::numeric_limits<double>::infinity();
};

// A wall at rest in the world frame.
inline MeshWall fixed_mesh_wall(std::shared_ptr<const geometry::WallField> field, int material, std::string name) {
  MeshWall wall;
  wall.field = std::move(field);
  wall.material = material;
  wall.name = std::move(name);
  return wall;
}

struct Box3 {
  Vec3 lo = Vec3::Constant(-1), hi = Vec3::Constant(1);
  bool contains(const Vec3& p) const { return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all(); }
};

// What the scene says, before any derived quantity exists.
struct ModelSpec {
  std::vector<Material> materials;
  std::vector<Interaction> interactions;
  ContactLawChoice law;  // by name, from the registry (contact_laws.hpp)
  Vec3 gravity = Vec3(0, 0, -9.81);
  std::optional<double> time_step;    // [s]; automatic when absent
  double time_step_fraction = 0.15;   // of the smaller of the Rayleigh and Hertz times
  double max_impact_speed = 1.0;      // [m/s] for the Hertz collision time
  std::optional<double> skin;         // [m]; default 0.5 of the largest radius
  Box3 domain;                        // particles leaving it are counted as lost
  std::vector<PlaneWall> planes;
  std::vector<MeshWall> meshes;
  double linear_stiffness = 0.0;      // [N/m] for the linear normal law
  double stop_overlap = 0.1;          // largest δ/R before the run stops (stability)
};

struct Model {
  std::vector<Material> materials;
  std::vector<PairParams> pair_table;  // [materials²], symmetric
  ContactLawChoice law;
  const CompiledContactLaw* contact_law = nullptr;  // its kernels, from the registry
  Vec3 gravity;
  double dt;                    // [s]
  double dt_rayleigh;           // [s] smallest Rayleigh time of the particles
  double dt_hertz;              // [s] Hertz collision time at max_impact_speed
  double skin;                  // [m]
  // [m] The farthest a grain in the domain lies from its rounded position at the last list build
  // (NeighbourList::x_at_build): the displacement check adds it, so that it bounds the shift from
  // the exact positions the list was built on, the same bound on every rank.
  double build_position_rounding;
  double cell_size;             // [m] neighbour grid
  double max_radius;            // [m]
  Box3 domain;
  std::vector<PlaneWall> planes;
  std::vector<MeshWall> meshes;
  std::vector<char> mesh_moves;  // [meshes] whether the wall's motion is not the identity
  // [meshes] farthest surface point from the wall's pivot [m]: a rotation by θ moves no point of
  // the wall farther than θ times this.
  std::vector<double> mesh_reach;
  double stop_overlap;
  std::string hash;             // of every parameter above: checkpoints carry it

  const PairParams& params(int a, int b) const {
    return pair_table[std::size_t(a) * materials.size() + std::size_t(b)];
  }
  int wall_count() const { return int(planes.size() + meshes.size()); }
};

// SHA-256 of the dem module's sources, for caches of simulated results.
std::string_view source_hash();

struct State;
// Checks the spec (throws diefill::InputError naming `source` and the field), mixes material
// pairs, calibrates damping, chooses the time step and skin for the particles in `state`.
Model compile_model(const ModelSpec& spec, const State& state, const std::string& source);

// InputError naming walls.<name>.motion when a wall at `top_speed` would move more than half the
// skin in a step: the grains near it are listed at a rebuild, and a rebuild comes once it has
// moved half the skin, so it could pass through grains it has not listed. compile_model checks
// every wall so; the pipeline asks it before a wall exists (pipeline/preflight.hpp).
void check_wall_travel(const std::string& name, double top_speed, double dt, double skin, const std::string& source);

}  // namespace dem
