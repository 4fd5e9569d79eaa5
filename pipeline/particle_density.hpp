#pragma once
// `diefill density PARTICLES --die MESH`: the density field (and, asked, the FEM hand-off) of any
// code's particle file on a die, by the pipeline's own density and FEM stages.
#include <filesystem>
#include <string>

namespace pipeline {

struct ParticleDensityRequest {
  std::filesystem::path particles;  // CSV or VTU
  std::filesystem::path die;        // the cavity's mesh (or a container)
  std::filesystem::path output;     // a folder, replaced whole once everything is written
  std::string units = "auto";       // the die file's unit: mm, m, in or auto
  std::string role = "cavity";
  double voxel_m = 0;               // 0: four grain radii
  std::string method = "exact";     // or gaussian
  double width_m = 0;               // Gaussian width (0: one voxel)
  double smoothed_width_m = 0;      // the smoothed field's width (0: half the largest grain diameter)
  double material_density = 0;      // [kg/m³]; 0: from the particle file
  double coarse_graining = 1;       // α of the file's grains over the real powder's (1: they are the powder)
  bool fem = false;                 // also the FEM hand-off (fem/)
  double element_size_m = 0;        // 0: the voxel
  bool quadratic = false;           // C3D10 instead of C3D4
};

// Writes the field, density.json and (fem) the hand-off into r.output; prints a line. Returns 0.
int particle_density(const ParticleDensityRequest& r);

}  // namespace pipeline
