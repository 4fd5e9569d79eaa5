#pragma once
// Vertex welding: a fold of a surface smaller than a weld distance (a CAD seam whose two ends
// miss each other by microns, so that its slivers fold over one another) closes when the
// vertices closer than that distance become one (docs/MESHES.md, "Mesh repair").
#include <cstddef>

#include "geometry/trimesh.hpp"

namespace mesh {

struct WeldedMesh {
  geometry::TriMesh mesh;  // the same vertex list with the welded vertices unused; triangles
                           // left with a repeated corner dropped
  std::size_t merged = 0;  // vertices moved onto another
  double moved_m = 0.0;    // the largest distance a vertex moved [m]: at most the weld distance
};

// Each vertex, in index order, that no earlier vertex took takes every later one closer than
// `distance` [m]: a welded vertex moves at most `distance` (no chains) and the result does not
// depend on the thread count or anything but the vertex order.
WeldedMesh weld_close_vertices(const geometry::TriMesh& mesh, double distance);

}  // namespace mesh
