#pragma once
// A density field with its statistics and exports (OpenVDB, VTK image, plot data).
#include <array>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "postprocess/density.hpp"

namespace post {

// A part of the cavity the report gives statistics for: each voxel's share in it (0..1).
struct Region {
  std::string name;
  std::vector<double> share;
};

struct DensityField {
  VoxelGrid grid;
  Vec3 centre = Vec3::Zero();          // [m] the die's axis (x, y): the sections pass through it
  std::vector<double> solid;           // [m³] solid volume per voxel (the kernel's, when smoothed)
  std::vector<double> cavity;          // cavity fraction per voxel, 0..1
  CorrectedField corrected;            // solid fraction per voxel
  double min_cavity = 0.25;            // the wall correction's threshold (and the profiles')
  double material_density = 0;         // [kg/m³]
  std::map<std::string, std::string> metadata;  // written into density.vdb
  // A seed ensemble's mean field carries the standard error of its seeds' mean (empty for one
  // run): per voxel of the solid fraction, and per column (index i × ny + j) of the columns' means.
  std::vector<double> solid_fraction_stderr, column_stderr;
};

// Each column's (i, j) cavity-weighted mean of the wall-corrected field, at i × ny + j; -1 where
// the column holds no cavity (the top view's values).
std::vector<double> column_means(const DensityField& field);

// An ensemble's pictures mark the columns whose standard error exceeds this fraction of the fill.
inline constexpr double stderr_marked_fraction = 0.02;

struct Profile {
  std::string axis;                    // "z", "r" or "x"
  std::vector<double> position;        // [m] bin centres
  std::vector<double> solid_fraction;  // cavity-weighted mean of its voxels' wall-corrected values
  std::vector<double> spread;          // cavity-weighted standard deviation of its voxels
  std::vector<double> cavity_volume;   // [m³] in the bin
};

struct RegionStatistics {
  std::string name;
  double cavity_volume_m3 = 0, solid_volume_m3 = 0, fill_ratio = 0;
};

struct FieldStatistics {
  double cavity_volume_m3 = 0, solid_volume_m3 = 0, fill_ratio = 0, mass_kg = 0;
  double mean = 0, std = 0, cv = 0, min = 0, max = 0;
  std::map<int, double> percentiles;  // 5, 25, 50, 75, 95: cavity-volume-weighted
  std::size_t voxels = 0, merged_voxels = 0;
  std::vector<Profile> profiles;
  std::vector<RegionStatistics> regions;  // filled by the caller, who knows the walls (region_statistics)
};

// Statistics over the voxels inside the cavity, weighted by their cavity volume; profiles over
// height, over the radius about the field's centre and along x (the shoe's path) in bins one
// voxel wide, leaving out bins with less cavity than the wall correction's threshold.
FieldStatistics statistics(const DensityField& field);

// Each region's cavity and solid volume on `grid`, from exactly binned `solid` [m³] and the
// cavity fractions, and their ratio.
std::vector<RegionStatistics> region_statistics(const VoxelGrid& grid, const std::vector<double>& solid,
                                                const std::vector<double>& cavity, const std::vector<Region>& regions);

// The die's outline where the views cut it: the opening seen from above (x, y), the section
// along the shoe's path (x, z at the centre's y) and across it (y, z at the centre's x) [m].
struct Outlines {
  std::vector<std::array<double, 4>> top, along, across;
};

// density.vdb: FloatGrids solid_fraction, density [kg/m³], cavity_fraction and merged (1 where
// the wall correction pooled the voxel with a neighbour) in world metres, with the field's
// metadata; with a smoothed field, its grids beside them as smoothed_solid_fraction,
// smoothed_density and smoothed_cavity_fraction on their own transform; an ensemble's also
// solid_fraction_stderr (and smoothed_solid_fraction_stderr). Written atomically.
void write_vdb(const DensityField& field, const DensityField* smoothed, const std::filesystem::path& path);
// A field's grids as VTK image cell data, for ParaView.
void write_vti(const DensityField& field, const std::filesystem::path& path);
// plot_data.json: the arrays plots.py draws (top view, sections, histogram, profiles, outlines).
void write_plot_data(const DensityField& field, const FieldStatistics& stats, const DensityField* smoothed,
                     const FieldStatistics* smoothed_stats,
                     const Outlines& outlines, const std::filesystem::path& path);

// One grid of a density.vdb as stored: its voxel edge, the centre of its voxel (0, 0, 0), its
// metadata, and its active voxels' values by index.
struct StoredGrid {
  double voxel_m = 0;
  Vec3 first_centre = Vec3::Zero();
  std::map<std::string, std::string> metadata;
  std::map<std::array<int, 3>, double> values;
};
// Every FloatGrid of a .vdb by name; throws InputError naming the file when it cannot be read.
std::map<std::string, StoredGrid> read_vdb(const std::filesystem::path& path);
// The grids as FloatGrids of a .vdb (fog volumes, world metres), with each grid's metadata; atomic.
void write_vdb(const std::map<std::string, StoredGrid>& grids, const std::filesystem::path& path);

}  // namespace post
