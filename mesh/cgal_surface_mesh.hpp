#pragma once
// Internal to the mesh module, and included by its CGAL translation units only (CGAL's headers
// are heavy, docs/ARCHITECTURE.md): the Surface_mesh those operations work on, and the copies
// between it and the project's TriMesh.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include "geometry/trimesh.hpp"

namespace mesh::detail {

using CgalKernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using CgalPoint = CgalKernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<CgalPoint>;

// Its triangles (faces of other sizes are left out), vertices numbered afresh: removed vertices
// and faces are skipped, so no garbage collection is needed before.
geometry::TriMesh to_trimesh(const SurfaceMesh& sm);

// The triangles as a Surface_mesh; false (and `out` untouched) when they do not form a polygon
// mesh: an edge shared the wrong way, or by more than two triangles.
bool to_surface_mesh(const geometry::TriMesh& mesh, SurfaceMesh& out);

}  // namespace mesh::detail
