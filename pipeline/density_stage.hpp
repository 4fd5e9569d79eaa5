#pragma once
// The density stage as the pipeline and `diefill density` run it: grains in, the wall-corrected
// field on the die's cavity out, with its statistics, exports and pictures.
#include <filesystem>
#include <functional>
#include <optional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mesh/die.hpp"
#include "postprocess/field.hpp"
#include "scene/choices.hpp"

namespace pipeline {

struct DensityOptions {
  double voxel_m = 1e-3;           // density voxel edge
  scene::DensityMethod method = scene::DensityMethod::exact;
  double width_m = 0;              // Gaussian width (default: one voxel)
  double min_cavity = 0.25;        // voxels with less cavity are merged with a neighbour
  int depth = 3;                   // cavity-fraction subdivision levels
  double smoothed_width_m = 0;     // > 0: also the Gaussian field of this width, on voxels as wide
  double coarse_graining = 1;      // of the grains, recorded in the fields' metadata
};

struct DensityResult {
  post::DensityField field;
  post::FieldStatistics stats;
  std::optional<post::DensityField> smoothed;
  post::FieldStatistics smoothed_stats;  // its profiles
  post::Outlines outlines;
};

// The regions of the report's statistics (their fill ratios are binned exactly on the smoothed
// field's finer grid when there is one), for a cavity whose opening is at `table` (positive
// distance_to_wall: into the cavity); the shoe travels +x, so the leading half is x below the
// die's centre (the half the shoe reaches first):
//   near_wall: voxels centred within `grain_diameter` of the die's walls or floor; core: the rest;
//   leading_half, trailing_half: either side of the centre (its own voxel row split in two);
//   bottom_quarter: the lowest quarter of the cavity's depth.
std::vector<post::Region> fill_regions(const post::VoxelGrid& grid, const post::Vec3& centre, double floor_z, double table_z,
                                       double grain_diameter, const std::function<double(const post::Vec3&)>& distance_to_wall);

// Throws InputError when no grain lies in the die's cavity (the wrong die, or wrong units).
DensityResult compute_density(const std::vector<post::Grain>& grains, const mesh::PreparedDie& die,
                              const geometry::WallField& walls, double material_density, const DensityOptions& settings,
                              const std::string& particles_source);

// A seed ensemble's field (pipeline/ensemble.hpp): its seeds' fields, on one grid and one cavity
// (the same die, scene and grain size), averaged voxel by voxel, with the standard error of the
// mean per voxel and per column; its statistics and profiles are the mean field's, its regions'
// fill ratios the seeds' means.
DensityResult mean_density(const std::vector<DensityResult>& seeds);

nlohmann::json statistics_json(const post::FieldStatistics& stats);

// density.vdb, density.vti, plot_data.json and the pictures into `dir` (a staging folder).
void write_density(const DensityResult& result, const std::filesystem::path& dir, bool pictures = true);

}  // namespace pipeline
