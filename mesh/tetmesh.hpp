#pragma once
// A tetrahedral mesh of a closed solid for finite-element codes (CGAL Mesh_3, in tetmesh.cpp
// alone: its headers are the heaviest of the project). Sharp edges of the surface are protected,
// so that they lie on mesh edges; docs/INTERFACE.md ("FEM hand-off") says how it is used.
#include <array>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/child_process.hpp"
#include "mesh/trimesh.hpp"

namespace mesh {

using Tet = std::array<int, 4>;

struct TetMeshOptions {
  double element_size_m = 1e-3;     // the largest edge of tetrahedra and boundary facets [m]
  double facet_distance_m = 2e-5;   // how far a boundary facet may lie from the surface [m]
  double feature_angle_deg = 60.0;  // surface edges sharper than this are protected
};

// The wait's stop was asked for: no mesh.
struct TetMeshingStopped : std::runtime_error {
  TetMeshingStopped() : std::runtime_error("tetrahedral meshing stopped") {}
};

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

// Meshes the solid bounded by `surface` (closed, outward), in a child process whose progress and
// stop `wait` gives. Deterministic: the same surface and options give the same mesh. Throws
// InputError naming `source` when CGAL cannot mesh it, TetMeshingStopped when `wait.stop` asks.
TetMesh tetrahedralise(const TriMesh& surface, const TetMeshOptions& options, const std::string& source,
                       const diefill::ChildWait& wait = {});

struct TetQuality {
  std::size_t inverted = 0;        // tetrahedra of zero or negative volume
  double min_dihedral_deg = 180;   // smallest dihedral angle of any tetrahedron
  double max_dihedral_deg = 0;
  double min_radius_ratio = 1;     // 3 r_in / r_circum: 1 regular, 0 flat
  double mean_radius_ratio = 0;
};
TetQuality tet_quality(const TetMesh& mesh);

double tet_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);  // signed [m³]

}  // namespace mesh
