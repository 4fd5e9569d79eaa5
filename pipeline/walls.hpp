#pragma once
// The walls of a die fill: the die's tool and its field (repaired and cached by the mesh stage),
// the shoe's field, the check that the grains can enter the cavity at all, and the model spec
// that holds them with the coarse-grained contact laws.
#include <filesystem>
#include <memory>

#include "dem/model.hpp"
#include "pipeline/plan.hpp"

namespace pipeline {

struct FillWalls {
  mesh::PreparedDie die;
  std::shared_ptr<const geometry::WallField> die_field, shoe_field;
  dem::ModelSpec spec;  // laws for the sized grains, gravity, the domain, walls "die" and "shoe"
  std::size_t shoe_wall = 0;  // its place in spec.meshes (the shoe pass gives it its motion)
  int powder = 0, steel = 0;  // material indices
  std::filesystem::path cache;  // OUT/.cache
};

// Throws InputError when the die cannot be repaired or the grains cannot enter its cavity.
FillWalls prepare_walls(const scene::PipelineScene& scene, const DieSource& source, const GrainSizing& grains, const ShoePlan& shoe);

// Upper bound of the radius of the largest sphere the cavity holds below the table.
double largest_inscribed_radius_bound(const geometry::WallField& die, const geometry::TriMesh& die_solid, const geometry::Box& cavity,
                                      double table_z, double spacing);

}  // namespace pipeline
