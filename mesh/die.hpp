#pragma once
// The mesh stage for one die, as the pipeline and `diefill sdf` run it: import, check and
// repair, build the solid the powder meets (the tool around a cavity, or the mesh itself), and
// its signed-distance field, cached by content hash and parameters.
#include <filesystem>
#include <optional>
#include <string>

#include "mesh/import.hpp"
#include "mesh/orientation.hpp"
#include "mesh/repair.hpp"
#include "mesh/sdf.hpp"
#include "mesh/tool.hpp"
#include "mesh/wall_role.hpp"

namespace mesh {

// Voxel edge as a fraction of the smallest grain radius. Trilinear interpolation of an exact
// distance field is exact on flat faces; on the ring's Ø10 mm core its error is h²/(8R) [m],
// and a grain's overlap is about 1 % of its radius: at h = R/4 for R = 0.5 mm the curvature
// error is 0.8 µm, a sixth of that overlap (see tests/test_sdf.cpp for the measured values).
inline constexpr double default_voxel_fraction = 0.25;

struct DieOptions {
  geometry::LengthUnit unit = geometry::LengthUnit::mm;
  WallRole role = WallRole::cavity;
  // The way the opening faces in the file; unset: found (find_opening) for a cavity, +z otherwise.
  std::optional<Up> up;
  // Where the table meets a cavity's part (docs/INTERFACE.md, `die.parting`).
  Parting parting = Parting::automatic;
  double voxel_m = 1.25e-4;         // voxel edge [m]
  double exterior_band_m = 1e-3;    // contact range plus neighbour skin plus one voxel [m]
  double interior_band_m = 2.5e-4;  // [m]
  RepairOptions repair;
  std::optional<TableExtent> table;  // cavity role: defaults to table_around(cavity, margin)
  double table_margin_m = 10e-3;
};

struct PreparedDie {
  std::string name;    // file stem
  std::string source;  // path as given
  std::string sha256;  // of the file's bytes
  geometry::LengthUnit unit = geometry::LengthUnit::mm;  // the file's
  bool unit_guessed = false;         // from its size, not given
  Up up;               // the way its opening faced in the file (now +z)
  bool up_found = false;  // found by looking, not given
  int part = 0;        // the body of the file it is for (DieFile); 0: the whole file
  std::optional<double> parting_z;  // [m] where the table cuts a part with no flat opening (DieFile)
  MeshReport before, after;          // checks before and after repair
  std::vector<std::string> actions;  // repair steps taken
  bool wrapped = false;
  double hausdorff_m = 0.0;   // existing surface moved by repair [m]
  double bridged_m = 0.0;     // widest gap new surface spans [m]
  geometry::TriMesh cavity;   // repaired mesh as given (the cavity, or the tool for role = tool) [m]
  geometry::TriMesh solid;    // what the powder meets: tool for role = cavity, else the mesh itself
  double table_z = 0.0;
  SdfGrid sdf;
  bool sdf_from_cache = false;
  std::string cache_key;
};

// A die's file as read, before any repair: the pipeline reads it once, plans the shoe and sizes
// the grains from its box, then prepares it with options that depend on them.
struct DieFile {
  std::string name;    // file stem
  std::string source;  // path as given
  std::string sha256;  // of the file's bytes
  geometry::LengthUnit unit = geometry::LengthUnit::mm;
  bool unit_guessed = false;  // from its size (guess_unit), not given
  Up up;                  // the way its opening faced in the file; the mesh is turned to face +z
  bool up_found = false;  // found by looking, not given
  // [m] turned: the height at which the die table cuts the part (its widest section), where
  // `parting` asks for it; the part above it is left to the upper punch. Unset: the table lies at
  // the part's flat top face.
  std::optional<double> parting_z;
  // The body of an assembly's file the die is for (`die.part`): 1 the largest by enclosed volume,
  // ties in the file's order; 0 the whole file. Bodies are the pieces that share no vertex
  // (separate_bodies); `bodies`: how many the file holds.
  int part = 0;
  std::size_t bodies = 0;
  geometry::TriMesh mesh;  // [m], turned: the whole file, or the part chosen
};
// Reads the file in `unit` (unset: guessed from its size, with a warning), keeps its body `part`
// (0: all of it) and turns it so that its opening faces +z (`up` unset: find_opening, or
// lying_flat for a part with no flat face that `parting` lets be cut). Throws InputError for a
// missing, empty or unreadable file, a part the file does not hold, and a part with no flat face
// when `parting` is Parting::opening.
DieFile read_die_file(const std::filesystem::path& path, std::optional<geometry::LengthUnit> unit, std::optional<Up> up = Up{},
                      Parting parting = Parting::automatic, int part = 0);

// The `up` to read a die's file with: the options' own, or for a cavity unset (its opening is
// found); a tool or a container is not turned.
std::optional<Up> up_to_read(const DieOptions& options);
// The parting to read it with: the options' own for a cavity; a tool or a container is not cut.
Parting parting_to_read(const DieOptions& options);

// Throws InputError for every defect of the file or the options (a die smaller than a few
// voxels, for instance, usually a mesh in metres read as millimetres).
PreparedDie prepare_die(const DieFile& file, const DieOptions& options, const std::optional<std::filesystem::path>& cache_dir);
PreparedDie prepare_die(const std::filesystem::path& path, const DieOptions& options,
                        const std::optional<std::filesystem::path>& cache_dir);

// Voxel and band for grains of largest radius R and neighbour skin s: the voxel is
// `voxel_fraction` R unless given; the band reaches R + s + one voxel outside the solid (the
// farthest a grain centre can be and still need the wall) and three voxels inside.
DieOptions die_options_for_grains(double grain_radius_m, double skin_m,
                                  std::optional<double> voxel_m = std::nullopt);

// The cache key: the file's bytes, how it was read and every parameter that changes the result.
std::string die_cache_key(const DieFile& file, std::optional<double> parting_z, const DieOptions& options);

}  // namespace mesh
