#pragma once
// Mesh checks and repair (CGAL Polygon Mesh Processing). A die or grain mesh must become a
// closed, outward-oriented, non-self-intersecting solid before a signed distance means anything.
// Repair never moves geometry by more than the user's tolerance without an error saying so.
#include <optional>
#include <string>
#include <vector>

#include "geometry/trimesh.hpp"

namespace mesh {

struct MeshReport {
  std::size_t triangles = 0;
  std::size_t vertices = 0;
  std::size_t boundary_edges = 0;      // edges with one triangle: holes
  std::size_t non_manifold_edges = 0;  // edges with three or more triangles
  std::size_t inconsistent_edges = 0;  // edges whose two triangles run the same way
  std::size_t degenerate_faces = 0;    // zero area (collinear or repeated vertices)
  std::size_t duplicate_faces = 0;     // same three vertices as an earlier triangle
  std::size_t self_intersections = 0;  // pairs of intersecting, non-adjacent triangles
  std::size_t shells = 0;              // edge-connected components
  bool closed = false;
  std::string orientation;  // "outward", "inward", "inconsistent" or "undefined (open)"
  double volume_m3 = 0.0;   // signed, by the divergence theorem
  double area_m2 = 0.0;
  geometry::Box bbox;
};

// All checks of the report, on a welded mesh as imported.
MeshReport inspect(const geometry::TriMesh& mesh);

struct RepairOptions {
  double tolerance_m = 5e-5;      // largest surface displacement repair may introduce
  double max_hole_m = 1e-3;       // holes up to this diameter are filled
  bool allow_wrap = true;         // fall back to alpha wrapping for what stays broken
  // A re-mesh may cover the surface where no grain of this diameter can touch it from the free
  // space (where grains move: the solid's inside for a cavity or a container, its outside for a
  // tool): a gap too narrow to enter (die_options_for_grains). Not counted as moving the surface;
  // reported.
  double closable_gap_m = 0.0;
  bool free_space_inside = true;
};

// Repair limits for a grain mesh clumped at the relative `clump_tolerance`: repair may move
// existing surface by a tenth of what the clump may deviate, and fills holes up to a tenth of
// the grain's size (a missing face of a decimated scan; the report's `bridged` says how far a
// patch reaches from the surface around it).
RepairOptions grain_repair_options(const geometry::TriMesh& grain, double clump_tolerance);

struct RepairResult {
  geometry::TriMesh mesh;  // closed, outward, without self-intersections
  MeshReport before, after;
  std::vector<std::string> actions;  // each step that changed something, human readable
  bool repaired = false;             // anything changed at all
  bool wrapped = false;              // alpha wrapping was used
  // Set when the winding-number solid was used: how far its re-meshing moved the surface [m].
  std::optional<double> winding_moved_m;
  std::size_t holes_filled = 0;
  // Largest distance from the input surface to the result [m]: how far repair moved existing
  // geometry; checked against the tolerance.
  double hausdorff_m = 0.0;
  // Largest distance from the result to the input surface [m]: how wide a gap (hole, crack,
  // groove) new surface spans; reported, not bounded, since no input geometry exists there.
  double bridged_m = 0.0;
};

// Repairs `mesh` or throws diefill::InputError naming `source` and the defect that could not
// be repaired within the tolerance (an open mesh with large holes, nested shells, a change
// larger than the tolerance, too few triangles).
RepairResult repair(const geometry::TriMesh& mesh, const RepairOptions& options, const std::string& source);

// A readable multi-line summary (for `diefill sdf` and logs).
std::string format_report(const MeshReport& report);

}  // namespace mesh
