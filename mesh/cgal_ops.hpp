#pragma once
// Internal to the mesh module: CGAL operations split into their own translation units so that
// the heavy headers compile in parallel on a 2-core machine.
#include <functional>
#include <limits>
#include <vector>

#include "geometry/trimesh.hpp"

namespace mesh::detail {

// CGAL's alpha wrapping (3D Alpha Wrapping, CGAL 5.5) of a triangle soup: a closed, manifold,
// outward surface at distance `offset` outside the input, bridging gaps narrower than `alpha`.
geometry::TriMesh alpha_wrap(const geometry::TriMesh& soup, double alpha, double offset);

// Largest distance from points sampled on `from` (a barycentric grid on each triangle, up to
// 16 points along an edge) to the surface of `to` [m]: one side of the Hausdorff distance.
// With `outside_target`, only points outside the closed solid `to` count: faces buried in it
// (inner lobes of a fold) bound no part of it, wherever they lie.
enum class Samples { all, outside_target };
double max_distance(const geometry::TriMesh& from, const geometry::TriMesh& to, Samples samples = Samples::all);
// The same over the sample points (with their face's unit normal) that `counts` accepts.
using SampleFilter = std::function<bool(const geometry::Vec3& point, const geometry::Vec3& unit_normal)>;
double max_distance(const geometry::TriMesh& from, const geometry::TriMesh& to, const SampleFilter& counts);
// That distance and the sample point of `from` it was measured at: where a repair moved the
// surface most, for a message that names the place; with `collect_beyond_m`, also every sample
// point `counts` accepts that lies farther than it: where a re-mesh should be finer.
struct FarthestSample {
  double distance_m = 0.0;
  geometry::Vec3 point = geometry::Vec3::Zero();
  geometry::Vec3 normal = geometry::Vec3::Zero();  // of the face `point` lies on
  std::vector<geometry::Vec3> beyond;
};
FarthestSample farthest_sample(const geometry::TriMesh& from, const geometry::TriMesh& to, const SampleFilter& counts,
                               double collect_beyond_m = std::numeric_limits<double>::infinity());

// Pairs of intersecting triangles that share no vertex; 0 for a clean mesh.
std::size_t count_self_intersections(const geometry::TriMesh& mesh);
// Per triangle: whether it is degenerate (two corners on one point, or all three on a line) or
// in one of those pairs.
std::vector<bool> faulty_triangles(const geometry::TriMesh& mesh);

// Re-meshes a closed shell where it folds through itself (CGAL's experimental self-intersection
// removal: local smoothing and hole filling). False when folds remain or the shell opens; then
// `shell` is unspecified. Its own translation unit: the header doubles union.cpp's build time.
bool remove_folds(geometry::TriMesh& shell);

}  // namespace mesh::detail

namespace mesh::detail {

struct UnionResult {
  geometry::TriMesh mesh;
  double moved_m = 0;               // largest distance a fold's removal moved its shell [m]
  std::size_t empty_shells = 0;     // closed shells enclosing no volume, dropped
  std::size_t unfolded_shells = 0;  // shells whose self-intersections were re-meshed
};

// Union of the solids closed shells enclose, by CGAL corefinement: shells that intersect each
// other (a gear set in mesh, engravings on a disc) are united exactly, no tolerance spent; a
// shell folded through itself (a decimated scan) is first re-meshed locally where it folds
// (`moved_m` says how far). Returns false when a shell is open or degenerate, a fold cannot be
// removed, or a union step fails; then `out` is unspecified.
bool union_of_shells(const geometry::TriMesh& closed_shells, UnionResult& out);

// The part of a closed, outward solid that crossing nowhere lies below the plane z = `height`,
// closed by its section there (CGAL's clip of the volume, which corefines: hence here). False
// when the result is not a closed manifold surface or is empty; then `out` is unspecified.
bool clip_below(const geometry::TriMesh& closed, double height, geometry::TriMesh& out);

}  // namespace mesh::detail
