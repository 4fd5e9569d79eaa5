// `diefill density PARTICLES --die MESH`: the density field of a particle file on a die.
#include <fmt/core.h>

#include <numbers>

#include "cli/commands.hpp"
#include "pipeline/density_stage.hpp"
#include "pipeline/fem_stage.hpp"
#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "dem/io.hpp"

namespace cli {

int run_density(const DensityCommand& c) {
  const std::optional<mesh::LengthUnit> unit = mesh::parse_unit_or_auto(c.units, "--units");
  const mesh::WallRole role = mesh::parse_role(c.role, "--role");
  if (role == mesh::WallRole::tool)
    throw diefill::InputError(c.die.string(), "--role", "a density field needs the cavity, not the tool body",
                              "Give the cavity mesh (role cavity) or a container");
  const dem::State particles = dem::read_particles(c.particles, 0, c.material_density);
  double r_max = 0, density_sum = 0;
  std::vector<post::Grain> grains;
  for (std::size_t i = 0; i < particles.size(); ++i) {
    r_max = std::max(r_max, particles.radius[i]);
    grains.push_back({particles.x[i], particles.radius[i], 1.0});
    density_sum += particles.mass[i] / (4.0 / 3.0 * std::numbers::pi * std::pow(particles.radius[i], 3));
  }
  const double material_density = c.material_density > 0 ? c.material_density : density_sum / double(particles.size());
  if (!(material_density > 0))
    throw diefill::InputError(c.particles.string(), "density", "the file gives no density",
                              "Add a density column or pass --material-density");
  // The field needs the cavity's volume per voxel, which exact wall queries give at any voxel
  // of the die's field; contacts are not computed here, so half a grain radius (not a quarter:
  // 8 times fewer voxels to build) seeds the queries.
  mesh::DieOptions sized = mesh::die_options_for_grains(r_max, 0.5 * r_max, 0.5 * r_max);
  sized.role = role;
  // Read as `diefill sdf` and `run` read a die: in the unit given, else in the one its size suggests.
  const mesh::DieFile file = mesh::read_die_file(c.die, unit, mesh::up_to_read(sized), mesh::parting_to_read(sized));
  sized.unit = file.unit;
  const mesh::PreparedDie die = mesh::prepare_die(file, sized, std::nullopt);
  const mesh::WallField walls = die.sdf.wall_field(die.solid);
  pipeline::DensitySettings s;
  s.voxel_m = c.voxel_mm > 0 ? c.voxel_mm * 1e-3 : 4 * r_max;
  s.method = c.method;
  s.width_m = c.width_mm * 1e-3;
  s.smoothed_width_m = c.smoothed_width_mm > 0 ? c.smoothed_width_mm * 1e-3 : r_max;  // as the pipeline: half a diameter
  s.coarse_graining = c.coarse_graining;
  const pipeline::DensityResult result = compute_density(grains, die, walls, material_density, s, c.particles.string());
  diefill::StagingFolder out(c.output);
  pipeline::write_density(result, out.path());
  nlohmann::json report = {{"die", {{"name", die.name}, {"source", die.source}, {"sha256", die.sha256}}},
                           {"particles", {{"source", c.particles.string()}, {"grains", grains.size()}}},
                           {"density", {{"voxel_m", s.voxel_m}, {"method", s.method}, {"smoothed_width_m", s.smoothed_width_m}, {"material_density", material_density},
                                        {"coarse_graining", c.coarse_graining}}},
                           {"fill", pipeline::statistics_json(result.stats)}};
  if (c.fem) {
    pipeline::FemSettings fem = pipeline::fem_settings(2 * r_max, s.voxel_m, c.element_size_mm * 1e-3);
    fem.quadratic = c.elements == "quadratic";
    report["fem"] = pipeline::write_fem_outputs({grains}, die, walls, material_density, result.stats.mass_kg, fem, out.path());
  }
  diefill::write_file_atomic(out / "density.json", report.dump(2) + "\n");
  out.commit();
  fmt::print("{}: mean solid fraction {:.4f} (std {:.4f}, min {:.4f}, max {:.4f}) over {} voxels; fill ratio {:.4f} -> {}\n",
             die.name, result.stats.mean, result.stats.std, result.stats.min, result.stats.max, result.stats.voxels,
             result.stats.fill_ratio, c.output.string());
  return 0;
}

}  // namespace cli
