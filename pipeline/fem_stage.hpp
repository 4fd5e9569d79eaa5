#pragma once
// The FEM hand-off stage (docs/INTERFACE.md, "FEM hand-off"): the cavity's tetrahedral mesh with
// the fill's solid fraction per element and node, the Abaqus/CalculiX files, and the worked
// CalculiX compaction example.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mesh/die.hpp"
#include "postprocess/density.hpp"

namespace pipeline {

// What the hand-off promises: its elements hold the cavity's mass (fill.mass_kg) to 0.5 %, measured
// before any correction (there is none); a run that misses it says so (stability.checks).
inline constexpr double fem_mass_tolerance = 0.005;

struct FemOptions {
  double element_size_m = 1.6e-3;
  double sub_voxel_m = 0.2e-3;     // the exact binning the elements' values are integrated from
  bool quadratic = false;          // C3D10 instead of C3D4
  bool compaction = true;          // run the CalculiX example (a warning when ccx is missing)
};

// The settings for grains of `grain_diameter` whose density field has voxels of `density_voxel`:
// elements of `element_size` (0: the density voxel), sub-voxels of a quarter grain diameter (at
// most an eighth of an element).
FemOptions fem_options(double grain_diameter, double density_voxel, double element_size);

// Writes `dir`/fem/ and returns the report's `fem` section; `mass_in_cavity_kg` is the density
// field's (fill.mass_kg), which the elements' mass is measured against (fem.mass_error_rel). Each
// realisation is one run's grains in the cavity; several (a seed ensemble's) give each element
// their mean and its standard error, on one mesh.
nlohmann::json write_fem_outputs(const std::vector<std::vector<post::Grain>>& realisations, const mesh::PreparedDie& die,
                                 const geometry::WallField& walls, double material_density, double mass_in_cavity_kg,
                                 const FemOptions& settings, const std::filesystem::path& dir);

}  // namespace pipeline
