// `diefill density PARTICLES --die MESH`: the command line's part; the work is
// pipeline::particle_density, in SI units.
#include "cli/commands.hpp"
#include "pipeline/particle_density.hpp"

namespace cli {

int run_density(const DensityCommand& c) {
  constexpr double mm = 1e-3;
  pipeline::ParticleDensityRequest r;
  r.particles = c.particles;
  r.die = c.die;
  r.output = c.output;
  r.units = c.units;
  r.role = c.role;
  r.voxel_m = c.voxel_mm * mm;
  r.method = c.method;
  r.width_m = c.width_mm * mm;
  r.smoothed_width_m = c.smoothed_width_mm * mm;
  r.material_density = c.material_density;
  r.coarse_graining = c.coarse_graining;
  r.fem = c.fem;
  r.element_size_m = c.element_size_mm * mm;
  r.quadratic = c.elements == "quadratic";
  return pipeline::particle_density(r);
}

}  // namespace cli
