// Exact union of intersecting closed shells, and the clip of a solid by a plane, by corefinement
// (CGAL PMP), in their own translation unit: corefinement is the heaviest CGAL header the project uses.
#include <CGAL/Polygon_mesh_processing/clip.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>

#include <cstdint>

#include "core/child_process.hpp"
#include "core/log.hpp"
#include "mesh/cgal_ops.hpp"
#include "mesh/cgal_surface_mesh.hpp"

namespace mesh::detail {

namespace {
namespace PMP = CGAL::Polygon_mesh_processing;

bool union_in_this_process(const geometry::TriMesh& closed_shells, UnionResult& out) {
  SurfaceMesh all;
  if (!to_surface_mesh(closed_shells, all)) {
    diefill::log::debug("union: the surface is not a polygon mesh");
    return false;
  }
  const double scale = geometry::bounding_box(closed_shells).size().maxCoeff();
  std::vector<SurfaceMesh> split, shells;
  PMP::split_connected_components(all, split);
  out.moved_m = 0;
  for (SurfaceMesh& s : split) {
    if (!CGAL::is_closed(s)) {
      diefill::log::debug("union: a shell of {} faces is open", s.number_of_faces());
      return false;
    }
    // Corefinement's other preconditions, unchecked in a release build of CGAL (a degenerate
    // face in 3DSMaxExport.stl crashed it): no zero-area faces.
    std::vector<SurfaceMesh::Face_index> degenerate;
    PMP::degenerate_faces(s, std::back_inserter(degenerate));
    if (!degenerate.empty()) {
      diefill::log::debug("union: a shell has {} degenerate faces", degenerate.size());
      return false;
    }
    // A shell that encloses nothing (two triangles back to back) adds nothing to the union.
    if (std::abs(PMP::volume(s)) < 1e-9 * scale * scale * scale) {
      ++out.empty_shells;
      continue;
    }
    if (!PMP::is_outward_oriented(s)) PMP::reverse_face_orientations(s);
    // A shell folded through itself (a decimated scan) is re-meshed where it folds: that moves
    // surface, measured against the shell as it was, on the faces left outside the result.
    if (PMP::does_self_intersect(s)) {
      const geometry::TriMesh folded = to_trimesh(s);
      geometry::TriMesh unfolded = folded;
      SurfaceMesh fixed;
      if (!remove_folds(unfolded) || !to_surface_mesh(unfolded, fixed)) {
        diefill::log::debug("union: the folds of a shell of {} faces could not be removed", s.number_of_faces());
        return false;
      }
      out.moved_m = std::max(out.moved_m, max_distance(folded, unfolded, Samples::outside_target));
      ++out.unfolded_shells;
      // Re-meshing may part a fold into separate shells (an inner lobe): each joins the union.
      std::vector<SurfaceMesh> parts;
      PMP::split_connected_components(fixed, parts);
      for (SurfaceMesh& part : parts) {
        if (!PMP::is_outward_oriented(part)) PMP::reverse_face_orientations(part);
        shells.push_back(std::move(part));
      }
      continue;
    }
    shells.push_back(std::move(s));
  }
  if (shells.empty()) return false;
  // Fold the shells into one; shells that do not touch the result are kept as they are by the
  // union as well (a union of disjoint solids is their juxtaposition).
  SurfaceMesh result = shells.front();
  for (std::size_t i = 1; i < shells.size(); ++i) {
    SurfaceMesh next;
    if (!PMP::corefine_and_compute_union(result, shells[i], next)) {
      diefill::log::debug("union: corefinement failed at shell {} of {}", i, shells.size());
      return false;
    }
    result = std::move(next);
  }
  out.mesh = to_trimesh(result);
  return true;
}

}  // namespace

// Corefinement runs in a child process: CGAL checks its preconditions only in debug builds, and
// some meshes that pass every check we can make still crash it (3DSMaxExport.stl of the shared
// broken meshes). A crash there must cost the union, not the user's run.
bool union_of_shells(const geometry::TriMesh& closed_shells, UnionResult& out) {
  const diefill::ChildResult child = diefill::run_in_child([&] {
    UnionResult united;
    const std::uint64_t ok = union_in_this_process(closed_shells, united) ? 1 : 0;
    return diefill::ByteWriter()
        .put(ok)
        .put(united.empty_shells)
        .put(united.unfolded_shells)
        .put(united.moved_m)
        .put(united.mesh.vertices)
        .put(united.mesh.triangles)
        .take();
  });
  if (child.outcome != diefill::ChildOutcome::done) {
    diefill::log::debug("union: corefinement ended abnormally (status {})", child.status);
    return false;
  }
  diefill::ByteReader in(child.bytes);
  std::uint64_t ok = 0;
  UnionResult united;
  in.get(ok);
  in.get(united.empty_shells);
  in.get(united.unfolded_shells);
  in.get(united.moved_m);
  in.get(united.mesh.vertices);
  in.get(united.mesh.triangles);
  if (!in.ok() || ok != 1) return false;
  out = std::move(united);
  return true;
}

bool clip_below(const geometry::TriMesh& closed, double height, geometry::TriMesh& out) {
  SurfaceMesh sm;
  if (!to_surface_mesh(closed, sm) || !CGAL::is_closed(sm)) return false;
  // The plane's negative side is kept: below z = height.
  if (!PMP::clip(sm, CgalKernel::Plane_3(0, 0, 1, -height), CGAL::parameters::clip_volume(true))) return false;
  sm.collect_garbage();
  if (sm.is_empty() || !CGAL::is_closed(sm)) return false;
  out = to_trimesh(sm);
  return true;
}

}  // namespace mesh::detail
