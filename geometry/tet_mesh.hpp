#pragma once
// A tetrahedral mesh as plain data, and the measures of its quality (tet_mesh.cpp): what the
// FEM hand-off passes to postprocess, which links no CGAL. mesh/tetmesh.hpp makes one (CGAL
// Mesh_3).
#include <array>
#include <cstddef>
#include <vector>

#include "geometry/trimesh.hpp"

namespace geometry {

using Tet = std::array<int, 4>;

struct TetMesh {
  std::vector<Vec3> nodes;  // [m]
  // Corner nodes, ordered so that (n1 - n0) x (n2 - n0) . (n3 - n0) > 0 (Abaqus' C3D4 and
  // VTK's tetra order).
  std::vector<Tet> tets;
  // Mesh edges on the protected sharp edges of the surface (node indices).
  std::vector<std::array<int, 2>> feature_edges;
  // Cells of zero volume on a flat part of the surface that the mesher left and this dropped.
  std::size_t dropped_boundary_slivers = 0;
};

struct TetQuality {
  std::size_t inverted = 0;        // tetrahedra of zero or negative volume
  double min_dihedral_deg = 180;   // smallest dihedral angle of any tetrahedron
  double max_dihedral_deg = 0;
  double min_radius_ratio = 1;     // 3 r_in / r_circum: 1 regular, 0 flat
  double mean_radius_ratio = 0;
};
TetQuality tet_quality(const TetMesh& mesh);

double tet_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);  // signed [m³]

}  // namespace geometry
