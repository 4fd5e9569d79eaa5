#pragma once
// The wall representation the simulation queries: a sparse voxel grid (exported from the
// OpenVDB narrow band) holding, per voxel, the signed distance and the index of the closest
// triangle, plus the triangle surface with its adjacency. Plain arrays, no OpenVDB types.
//
// Why both: trilinear interpolation of any exact distance field is wrong by up to about a
// quarter voxel on the medial surface of concave edges (the distance has a kink there), and a
// single nearest distance feels only one face of a concave corner. So a query takes the closest
// triangles stored at the eight corners of the voxel cell around a point as candidates, walks
// each down to a local minimum of the distance over the surface, and returns every distinct
// minimum: exact distances, one contact per face of a concave corner, one (not two) at a convex
// edge. The cost depends on the voxel lookup and a few triangle tests, not on the mesh's size.
#include <array>
#include <cstdint>
#include <vector>

#include "core/huge_pages.hpp"
#include "geometry/trimesh.hpp"

namespace geometry {

// Where on a triangle a closest point lies.
enum class Feature : std::uint8_t { face, edge, vertex };

struct ClosestPoint {
  Vec3 point;
  Feature feature;
  int index;  // face: the triangle; edge: local edge k (v_k to v_k+1); vertex: local vertex k
};
// Closest point to p on triangle abc with the feature it lies on.
ClosestPoint closest_feature(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

struct SurfacePoint {
  Vec3 point;            // closest point on the surface [m]
  Vec3 normal;           // unit, from the surface towards the query point (outward if on it)
  double distance;       // signed [m]: negative when the query point is inside the solid
  int triangle;          // a triangle the point lies on
  std::uint64_t feature; // identifies the face, edge or vertex, for merging duplicates
};

// Contact normals closer than this belong to one smooth surface (the sharp-edge angle of
// mesh::sharp_edges uses the same figure).
inline constexpr double smooth_angle_deg = 30.0;

// What a wall query reads of one triangle, in one record of two cache lines: a query near a
// finely tessellated wall touches triangles no other grain touches, and reading the corners,
// normal and neighbours from five arrays cost a cache miss each (against the pair stage, the wall
// stage ran 1.65 times slower on a million triangles than on 4,092, with 1.30 triangle tests per
// query against 1.11).
struct alignas(64) WallFace {
  std::array<Vec3, 3> corner;       // [m]
  Vec3 normal;                      // unit, outward
  Triangle vertex;                  // indices into WallField::vertices
  std::array<int, 3> neighbour;     // across local edge k (corner k to k+1); -1 on a boundary
};
static_assert(sizeof(WallFace) == 128, "two cache lines: WallField::prefetch fetches both");

// What the queries read at random, grain by grain: on huge pages when large (a million-triangle
// wall's faces span 128 MB).
template <class T>
using QueryArray = std::vector<T, diefill::HugePageAllocator<T>>;

struct WallField {
  // Surface (metres), with adjacency for the local descent and angle-weighted pseudo-normals
  // for the sign (Bærentzen & Aanæs 2005).
  std::vector<Vec3> vertices;
  std::vector<Triangle> triangles;
  QueryArray<WallFace> faces;                  // per triangle, what the queries read
  QueryArray<Vec3> vertex_normals;             // angle-weighted
  QueryArray<int> vertex_face_offsets;         // CSR: faces around each vertex
  QueryArray<int> vertex_faces;

  // Sparse voxels: bricks of 8x8x8 voxels; voxel (i, j, k) sits at (i, j, k) * voxel.
  double voxel = 0.0;                    // [m]
  // Beyond the band the distance is known only to exceed the band's width on that side: the
  // free side reports +free_band, the solid side -solid_band (lower bounds of |distance|).
  float free_band = 0.0f;                // [m]
  float solid_band = 0.0f;               // [m]
  std::array<int, 3> brick_min{}, brick_count{};  // dense brick index box, in bricks
  QueryArray<std::int32_t> brick_of_cell;  // >= 0: brick; -1: no brick, outside; -2: inside
  QueryArray<float> distance;           // 512 per brick [m]
  QueryArray<std::int32_t> closest;     // 512 per brick; -1 where the voxel is not in the band

  std::size_t memory_bytes() const;

  // True when all eight voxels around p are in the band.
  bool band_cell(const Vec3& p) const;
  // Trilinear signed distance [m] (+free_band or -solid_band beyond the band).
  double trilinear(const Vec3& p) const;
  // Exact signed distance to the surface near p (within the band), from the local minima;
  // falls back to trilinear() beyond the band.
  double signed_distance(const Vec3& p) const;
  // Every distinct local minimum of the distance to the surface within `range` of p, written
  // to `out` (at most `capacity`); returns how many were found. Minima on one smooth surface
  // (normals within smooth_angle_deg) count once, at the deepest.
  int local_minima(const Vec3& p, double range, SurfacePoint* out, int capacity) const;
  // The same, tracked from a point's previous query: `seeds` (count of them, at most 8) start as
  // the closest triangles of p's cell (cell_of, cell_candidates) and are replaced by where their
  // walks to a local minimum ended, so that the next query of a point that moved a little walks
  // over a triangle or none, however finely the surface is tessellated (a walk from a voxel
  // corner crosses as many triangles as fit in a voxel: hundreds of slivers). A walk that
  // crossed a sharp edge (normals more than smooth_angle_deg apart) also leaves a watch on the
  // surface it left, where a minimum of its own may appear as the point moves on. Minima are
  // the same whichever seeds lead to them (one feature, one result, bit for bit) and come in the
  // order of their features.
  int local_minima_tracked(const Vec3& p, double range, std::int32_t* seeds, std::int32_t& count,
                           SurfacePoint* out, int capacity) const;
  // Asks the memory for the faces a tracked query will start from (seeds as above), so that a
  // loop over grains can fetch the next grains' faces while it queries this one's.
  // The seeds may be another thread's, being written as they are read (the grains ahead of a
  // thread's share are the next thread's first): read atomically, any value read is a valid seed
  // and a count from -1 to 8, and a prefetch changes no result.
  void prefetch(const std::int32_t* seeds, const std::int32_t* count) const {
    const std::int32_t n = __atomic_load_n(count, __ATOMIC_RELAXED);
    for (std::int32_t c = 0; c < n; ++c) {
      const std::int32_t seed = __atomic_load_n(&seeds[c], __ATOMIC_RELAXED);
      const char* face = reinterpret_cast<const char*>(&faces[std::size_t(seed < 0 ? ~seed : seed)]);
      __builtin_prefetch(face);
      __builtin_prefetch(face + 64);
    }
  }
  // Integer coordinates of the voxel cell containing p, and the distinct closest triangles of
  // its eight corners (at most 8).
  std::array<int, 3> cell_of(const Vec3& p) const;
  int cell_candidates(const std::array<int, 3>& cell, std::int32_t* out) const;
  // The closest surface point found from the candidates of the voxels around p: the cell's 8
  // corners (reach 0), or the 3x3x3 voxels centred on the voxel nearest to p (reach 1, for
  // grid nodes). False beyond the band.
  bool nearest(const Vec3& p, int reach, SurfacePoint& out) const;

  // Builds the surface half (adjacency, normals) from a closed, outward mesh.
  void set_surface(const TriMesh& mesh);

 private:
  bool voxel_at(int i, int j, int k, float& value, std::int32_t& triangle) const;
  // Distinct closest triangles of the voxels around p (see nearest); returns their number.
  int candidates(const Vec3& p, int reach, std::int32_t* out, int capacity) const;
  // The local minimum a walk from `triangle` ends at. `anchor` (if given) receives the last
  // triangle before the walk first crossed a sharp edge (normals more than smooth_angle_deg
  // apart), or -1; with `stop_at_sharp_edge` the walk ends there.
  SurfacePoint descend(const Vec3& p, int triangle, int* anchor = nullptr, bool stop_at_sharp_edge = false) const;
  int descend_all(const Vec3& p, const std::int32_t* triangles_near, int count, SurfacePoint* out) const;
  // These minima (n of them, in `found`), replaced by those of the 3x3x3 voxels when they
  // disagree in sign, with those of the nearest one's sign kept (at most 27); `widened` (if
  // given) tells whether the wider voxels were asked.
  int consistent_minima(const Vec3& p, SurfacePoint* found, int n, bool* widened) const;
  // Distinct minima within `range`, one per smooth surface, in the order of their features.
  static int merged_minima(SurfacePoint* minima, int n, double range, SurfacePoint* out, int capacity);
};

}  // namespace geometry
