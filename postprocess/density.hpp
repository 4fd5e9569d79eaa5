#pragma once
// Density fields on the die geometry (module `post`). Grain volume is split exactly among the
// voxels it overlaps; each voxel's solid volume is divided by the part of the voxel inside the
// cavity, so that voxels cut by the wall are not biased low; voxels with too little cavity to
// carry a value are pooled with their fullest neighbour, both flagged.
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <vector>

namespace post {

using Vec3 = Eigen::Vector3d;

struct Grain {
  Vec3 centre;        // [m]
  double radius;      // [m]
  double weight = 1;  // volume multiplier: a clump member's share of its grain's true volume
};

// A regular grid of voxels; voxel (i, j, k) spans origin + h [i, i+1) x [j, j+1) x [k, k+1).
struct VoxelGrid {
  Vec3 origin = Vec3::Zero();  // [m] corner of voxel (0, 0, 0)
  double voxel = 1e-3;         // [m]
  int nx = 0, ny = 0, nz = 0;

  std::size_t size() const { return std::size_t(nx) * std::size_t(ny) * std::size_t(nz); }
  std::size_t index(int i, int j, int k) const {
    return (std::size_t(i) * std::size_t(ny) + std::size_t(j)) * std::size_t(nz) + std::size_t(k);
  }
  Vec3 centre(int i, int j, int k) const { return origin + voxel * Vec3(i + 0.5, j + 0.5, k + 0.5); }
  double voxel_volume() const { return voxel * voxel * voxel; }
};

// The grid covering [lo, hi] with voxels of edge h, aligned so that a voxel's centre lies at
// anchor.x(), anchor.y() (the die's axis: its sections are then voxel rows) and a voxel face at
// anchor.z() (the die table: no voxel straddles the opening).
VoxelGrid grid_covering(const Vec3& lo, const Vec3& hi, double h, const Vec3& anchor);

// Adds each grain's volume inside each voxel [m³] (exact sphere-box intersections); the part of
// a grain outside the grid is not counted.
void bin_exact(const std::vector<Grain>& grains, const VoxelGrid& grid, std::vector<double>& solid);

// Gaussian coarse graining (after MercuryCG): each grain's volume spread from its centre with a
// normalised Gaussian of standard deviation `width`, cut at 3 widths along each axis and
// normalised on the lattice of nodes (on the grid or not: a grid that is to keep every grain's
// weight reaches 3 widths past them).
void bin_gaussian(const std::vector<Grain>& grains, const VoxelGrid& grid, double width, std::vector<double>& solid);
// The part of each voxel inside the cavity (0..1) and that part's centroid [m].
struct CavityVolumes {
  std::vector<double> fraction;
  std::vector<Vec3> centroid;
};

// The cavity smoothed by the same kernel: the denominator of the kernel method. Each voxel's
// cavity is taken as a cube at its centroid and the Gaussian integrated over it (as points at
// the voxels' centres, the cavity's edge sits up to half a voxel off and a lattice's ratio read
// 2-3 % off a voxel from the floor: measured on the ring).
std::vector<double> smooth_gaussian(const VoxelGrid& grid, const CavityVolumes& cavity, double width);

// The part of each voxel inside the cavity: the free side of the walls (`distance` positive;
// beyond a known range a lower bound of the magnitude is enough) within the box [lo, hi] (the
// cavity's bounds: the table's plane on top). A cube farther from the wall than its
// half-diagonal is wholly free or not; a cut cube is split in eight, down to `depth` levels,
// where a cube of side a takes clamp(1/2 + d/a, 0, 1) (exact for a face-parallel wall), with
// the fractions within rounding of 0 or 1 snapped to them (else the tool's top, half a leaf
// below the table's plane, reads 1e-17 of cavity and turns voxels outside the die into cavity).
CavityVolumes cavity_fractions(const VoxelGrid& grid, const std::function<double(const Vec3&)>& distance, const Vec3& lo,
                               const Vec3& hi, int depth);

struct CorrectedField {
  std::vector<double> solid_fraction;  // solid volume over cavity volume, NaN outside the cavity
  std::vector<std::uint8_t> merged;    // 1 where the voxel's value is a pool's (a sliver or its host)
  std::size_t merged_count = 0;
};

// Wall correction: solid / (cavity fraction * voxel volume). Voxels whose cavity fraction is
// below `min_cavity` are pooled with the 6-neighbour of largest cavity fraction, never divided
// by nearly nothing; every voxel of a pool carries the pool's solid over its cavity, so that
// Σ solid fraction × cavity volume is the solid in the cavity's voxels exactly.
CorrectedField correct_for_walls(const VoxelGrid& grid, const std::vector<double>& solid,
                                 const std::vector<double>& cavity, double min_cavity);

}  // namespace post
