#include "pipeline/particle_density.hpp"

#include <fmt/core.h>

#include <cmath>
#include <numbers>
#include <nlohmann/json.hpp>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "dem/io.hpp"
#include "mesh/die.hpp"
#include "pipeline/density_stage.hpp"
#include "pipeline/fem_stage.hpp"

namespace pipeline {

int particle_density(const ParticleDensityRequest& r) {
  const std::optional<geometry::LengthUnit> unit = geometry::parse_unit_or_auto(r.units, "--units");
  const mesh::WallRole role = mesh::parse_role(r.role, "--role");
  const scene::DensityMethod method = diefill::parse_choice(scene::density_methods, r.method, "--method");
  if (role == mesh::WallRole::tool)
    throw diefill::InputError(r.die.string(), "--role", "a density field needs the cavity, not the tool body",
                              "Give the cavity mesh (role cavity) or a container");
  const dem::State particles = dem::read_particles(r.particles, 0, r.material_density);
  double r_max = 0, density_sum = 0;
  std::vector<post::Grain> grains;
  for (std::size_t i = 0; i < particles.size(); ++i) {
    r_max = std::max(r_max, particles.radius[i]);
    grains.push_back({particles.x[i], particles.radius[i], 1.0});
    density_sum += particles.mass[i] / (4.0 / 3.0 * std::numbers::pi * std::pow(particles.radius[i], 3));
  }
  const double material_density = r.material_density > 0 ? r.material_density : density_sum / double(particles.size());
  if (!(material_density > 0))
    throw diefill::InputError(r.particles.string(), "density", "the file gives no density",
                              "Add a density column or pass --material-density");
  // The field needs the cavity's volume per voxel, which exact wall queries give at any voxel
  // of the die's field; contacts are not computed here, so half a grain radius (not a quarter:
  // 8 times fewer voxels to build) seeds the queries.
  mesh::DieOptions sized = mesh::die_options_for_grains(r_max, 0.5 * r_max, 0.5 * r_max);
  sized.role = role;
  // Read as `diefill sdf` and `run` read a die: in the unit given, else in the one its size suggests.
  const mesh::DieFile file = mesh::read_die_file(r.die, unit, mesh::up_to_read(sized), mesh::parting_to_read(sized));
  sized.unit = file.unit;
  const mesh::PreparedDie die = mesh::prepare_die(file, sized, std::nullopt);
  const geometry::WallField walls = die.sdf.wall_field(die.solid);
  DensityOptions s;
  s.voxel_m = r.voxel_m > 0 ? r.voxel_m : 4 * r_max;
  s.method = method;
  s.width_m = r.width_m;
  s.smoothed_width_m = r.smoothed_width_m > 0 ? r.smoothed_width_m : r_max;  // as the pipeline: half a diameter
  s.coarse_graining = r.coarse_graining;
  const DensityResult result = compute_density(grains, die, walls, material_density, s, r.particles.string());
  diefill::StagingFolder out(r.output);
  write_density(result, out.path());
  nlohmann::json report = {{"die", {{"name", die.name}, {"source", die.source}, {"sha256", die.sha256}}},
                           {"particles", {{"source", r.particles.string()}, {"grains", grains.size()}}},
                           {"density", {{"voxel_m", s.voxel_m}, {"method", std::string(diefill::choice_name(scene::density_methods, s.method))}, {"smoothed_width_m", s.smoothed_width_m}, {"material_density", material_density},
                                        {"coarse_graining", r.coarse_graining}}},
                           {"fill", statistics_json(result.stats)}};
  if (r.fem) {
    FemOptions fem = fem_options(2 * r_max, s.voxel_m, r.element_size_m);
    fem.quadratic = r.quadratic;
    report["fem"] = write_fem_outputs({grains}, die, walls, material_density, result.stats.mass_kg, fem, out.path());
  }
  diefill::write_file_atomic(out / "density.json", report.dump(2) + "\n");
  out.commit();
  fmt::print("{}: mean solid fraction {:.4f} (std {:.4f}, min {:.4f}, max {:.4f}) over {} voxels; fill ratio {:.4f} -> {}\n",
             die.name, result.stats.mean, result.stats.std, result.stats.min, result.stats.max, result.stats.voxels,
             result.stats.fill_ratio, r.output.string());
  return 0;
}

}  // namespace pipeline
