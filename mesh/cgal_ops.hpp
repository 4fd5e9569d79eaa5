#pragma once
// Internal to the mesh module: CGAL operations split into their own translation units so that
// the heavy headers compile in parallel on a 2-core machine.
#include "mesh/trimesh.hpp"

namespace mesh::detail {

// CGAL's alpha wrapping (3D Alpha Wrapping, CGAL 5.5) of a triangle soup: a closed, manifold,
// outward surface at distance `offset` outside the input, bridging gaps narrower than `alpha`.
TriMesh alpha_wrap(const TriMesh& soup, double alpha, double offset);

// Largest distance from points sampled on `from` (a barycentric grid on each triangle, up to
// 16 points along an edge) to the surface of `to` [m]: one side of the Hausdorff distance.
double max_distance(const TriMesh& from, const TriMesh& to);

// Pairs of intersecting triangles that share no vertex; 0 for a clean mesh.
std::size_t count_self_intersections(const TriMesh& mesh);

}  // namespace mesh::detail

namespace mesh::detail {

// Union of closed shells that intersect each other but not themselves (a gear set in mesh,
// engravings on a disc), by CGAL corefinement: exact, no tolerance spent. Returns false when a
// shell is open or intersects itself, or a union step fails; then `out` is unspecified.
bool union_of_shells(const TriMesh& closed_shells, TriMesh& out);

}  // namespace mesh::detail
