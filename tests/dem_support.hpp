#pragma once
// Small DEM scenes for the physics tests.
#include <memory>

#include "dem/model.hpp"
#include "dem/state.hpp"
#include "dem/step.hpp"
#include "mesh/die.hpp"
#include "mesh/repair.hpp"
#include "mesh/sdf.hpp"

namespace test {

inline dem::Material glass(double e = 0.5, double mu = 0.0) {
  dem::Material m;
  m.name = "glass";
  m.density = 2500;
  m.youngs_modulus = 1e8;
  m.poisson_ratio = 0.25;
  m.restitution = e;
  m.sliding_friction = mu;
  return m;
}

// A wall material so stiff that E* is the grain's E/(1-ν²) to 1e-12 (docs/PHYSICS.md §2).
inline dem::Material rigid_wall(double e = 0.5, double mu = 0.0) {
  dem::Material m = glass(e, mu);
  m.name = "rigid";
  m.youngs_modulus = 1e22;
  return m;
}

inline dem::ModelSpec spec_with(std::vector<dem::Material> materials, dem::Vec3 gravity = dem::Vec3::Zero()) {
  dem::ModelSpec spec;
  spec.materials = std::move(materials);
  spec.gravity = gravity;
  spec.domain.lo = dem::Vec3::Constant(-0.1);
  spec.domain.hi = dem::Vec3::Constant(0.1);
  return spec;
}

// The wall field of a closed solid given as a mesh (the tool side of the walls).
inline std::shared_ptr<const geometry::WallField> wall_field_of(const geometry::TriMesh& solid, double voxel) {
  mesh::SdfOptions o;
  o.voxel_m = voxel;
  o.exterior_band_m = 8 * voxel;
  o.interior_band_m = 2 * voxel;
  const mesh::SdfGrid sdf = mesh::build_sdf(solid, o);
  return std::make_shared<const geometry::WallField>(sdf.wall_field(solid));
}

}  // namespace test
