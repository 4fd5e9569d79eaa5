#pragma once
// Narrow-band signed-distance fields (OpenVDB FloatGrid) of closed solids: metres, negative
// inside the solid, trilinear sampling. OpenVDB types stay inside sdf.cpp.
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "geometry/trimesh.hpp"
#include "geometry/wall_field.hpp"

namespace mesh {

struct SdfOptions {
  double voxel_m = 1e-4;          // voxel edge [m]
  double exterior_band_m = 1e-3;  // the band reaches this far outside the solid [m]
  double interior_band_m = 2e-4;  // and this far inside [m]
  // The mesh bounds the free space (a container, triangles facing inwards): the free side is
  // the mesh's inside, and the bands swap accordingly.
  bool inside_out = false;
};

// Sampled values of one voxel's eight cell corners, for exact density corrections and for
// exporting to the simulation's own sparse layout.
struct SdfLeaf {
  std::array<int, 3> origin;         // index of the leaf's first voxel
  std::array<float, 512> values;     // 8x8x8, x slowest: values[(i*8 + j)*8 + k]
  std::array<bool, 512> active;
};

class SdfGrid {
 public:
  SdfGrid();
  ~SdfGrid();
  SdfGrid(SdfGrid&&) noexcept;
  SdfGrid& operator=(SdfGrid&&) noexcept;

  double voxel_size() const;          // [m]
  double background() const;          // |distance| OpenVDB reports beyond the band [m]
  std::size_t active_voxels() const;
  std::size_t memory_bytes() const;
  geometry::Box active_bounds() const;  // world bounds of the active voxels [m]

  // Trilinear distance [m]; ± background outside the band.
  double sample(const geometry::Vec3& p) const;
  // True when all eight corners around p are active, so that sample(p) is a band value.
  bool in_band(const geometry::Vec3& p) const;
  // Value at voxel (i, j, k), which sits at world position (i, j, k) * voxel_size.
  float voxel_value(int i, int j, int k) const;
  // World positions of active voxels (every `stride`-th, in a fixed order).
  std::vector<geometry::Vec3> active_voxel_positions(std::size_t stride = 1) const;
  std::vector<SdfLeaf> leaves() const;

  // The simulation's wall representation: voxels with distances and closest triangles, plus
  // the surface `solid` the grid was built from.
  geometry::WallField wall_field(const geometry::TriMesh& solid) const;

  const std::map<std::string, std::string>& metadata() const;
  void set_metadata(const std::string& key, const std::string& value);

  // Atomic write of the float grid "sdf" (with its metadata, voxel size and units): the user's
  // file, which any OpenVDB reader opens.
  void write(const std::filesystem::path& path) const;
  // The same plus the Int32 grid "closest_triangle", for the mesh stage's cache only (OpenVDB's
  // Python module refuses a whole file that holds an Int32 grid).
  void write_cache(const std::filesystem::path& path) const;
  // Reads what write_cache wrote; throws InputError when the file is unreadable or lacks a grid.
  static SdfGrid read_cache(const std::filesystem::path& path);

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
  friend SdfGrid build_sdf(const geometry::TriMesh&, const SdfOptions&);
};

// Exact narrow-band distances of a closed, outward-oriented triangle mesh, with the closest
// triangle of every band voxel. OpenVDB's renormalisation is disabled: it was measured to shift
// flat-face distances by up to 0.06 voxel.
SdfGrid build_sdf(const geometry::TriMesh& solid, const SdfOptions& options);

// The wall field of a solid that grains of largest radius r touch only through exact queries:
// voxels of r/2 merely seed the search for candidate triangles, and the band reaches a grain
// centre in contact range plus a skin of r/2 (a shoe, a pedestal, a block).
geometry::WallField contact_wall_field(const geometry::TriMesh& solid, double grain_radius);

}  // namespace mesh
