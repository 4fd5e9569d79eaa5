#pragma once
// A tetrahedral mesh of a closed solid for finite-element codes (CGAL Mesh_3, in tetmesh.cpp
// alone: its headers are the heaviest of the project). Sharp edges of the surface are protected,
// so that they lie on mesh edges; docs/INTERFACE.md ("FEM hand-off") says how it is used.
#include <array>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/child_process.hpp"
#include "geometry/tet_mesh.hpp"

namespace mesh {

struct TetMeshOptions {
  double element_size_m = 1e-3;     // the largest edge of tetrahedra and boundary facets [m]
  double facet_distance_m = 2e-5;   // how far a boundary facet may lie from the surface [m]
  double feature_angle_deg = 60.0;  // surface edges sharper than this are protected
};

// The wait's stop was asked for: no mesh.
struct TetMeshingStopped : std::runtime_error {
  TetMeshingStopped() : std::runtime_error("tetrahedral meshing stopped") {}
};

// Meshes the solid bounded by `surface` (closed, outward), in a child process whose progress and
// stop `wait` gives. Deterministic: the same surface and options give the same mesh. Throws
// InputError naming `source` when CGAL cannot mesh it, TetMeshingStopped when `wait.stop` asks.
geometry::TetMesh tetrahedralise(const geometry::TriMesh& surface, const TetMeshOptions& options, const std::string& source,
                                 const diefill::ChildWait& wait = {});

}  // namespace mesh
