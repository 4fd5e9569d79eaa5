#pragma once
// A density field with its statistics and exports (OpenVDB, VTK image, plot data).
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "postprocess/density.hpp"

namespace post {

struct DensityField {
  VoxelGrid grid;
  std::vector<double> solid;           // [m³] solid volume per voxel
  std::vector<double> cavity;          // cavity fraction per voxel, 0..1
  CorrectedField corrected;            // solid fraction per voxel
  double material_density = 0;         // [kg/m³]
  std::map<std::string, std::string> metadata;  // written into density.vdb
};

struct Profile {
  std::string axis;              // "z", "r" or "x"
  std::vector<double> position;  // [m] bin centres
  std::vector<double> solid_fraction;  // cavity-volume-weighted mean in the bin
  std::vector<double> cavity_volume;   // [m³] in the bin
};

struct FieldStatistics {
  double cavity_volume_m3 = 0, solid_volume_m3 = 0, fill_ratio = 0, mass_kg = 0;
  double mean = 0, std = 0, cv = 0, min = 0, max = 0;
  std::map<int, double> percentiles;  // 5, 25, 50, 75, 95: cavity-volume-weighted
  std::size_t voxels = 0, merged_voxels = 0;
  std::vector<Profile> profiles;
};

// Statistics over the voxels inside the cavity, weighted by their cavity volume; profiles over
// height, over the radius about `axis_xy` and along x (the shoe's path), in `bins` bins.
FieldStatistics statistics(const DensityField& field, const Vec3& axis_xy, int bins);

// density.vdb: FloatGrids solid_fraction, density [kg/m³], cavity_fraction in world metres, with
// the field's metadata; written atomically.
void write_vdb(const DensityField& field, const std::filesystem::path& path);
// density.vti: the same grids as VTK image cell data, for ParaView.
void write_vti(const DensityField& field, const std::filesystem::path& path);
// plot_data.json: the arrays plots.py draws (top view, section, histogram, profiles).
void write_plot_data(const DensityField& field, const FieldStatistics& stats, const std::filesystem::path& path);

}  // namespace post
