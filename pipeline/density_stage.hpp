#pragma once
// The density stage as the pipeline and `diefill density` run it: grains in, the wall-corrected
// field on the die's cavity out, with its statistics, exports and pictures.
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mesh/die.hpp"
#include "postprocess/field.hpp"

namespace app {

struct DensitySettings {
  double voxel_m = 1e-3;           // density voxel edge
  std::string method = "exact";    // "exact" | "gaussian"
  double width_m = 0;              // Gaussian width (default: one voxel)
  double min_cavity = 0.25;        // voxels with less cavity are merged with a neighbour
  int depth = 3;                   // cavity-fraction subdivision levels
};

struct DensityResult {
  post::DensityField field;
  post::FieldStatistics stats;
};

// Throws InputError when no grain lies in the die's cavity (the wrong die, or wrong units).
DensityResult compute_density(const std::vector<post::Grain>& grains, const mesh::PreparedDie& die,
                              const mesh::WallField& walls, double material_density, const DensitySettings& settings,
                              const std::string& particles_source);

nlohmann::json statistics_json(const post::FieldStatistics& stats);

// density.vdb, density.vti, plot_data.json and the pictures into `dir` (a staging folder).
void write_density(const DensityResult& result, const std::filesystem::path& dir);

}  // namespace app
