#pragma once
// Internal to the mesh module: the solid a messy surface means, as the region where its
// generalized winding number (geometry/winding.hpp) is at least ½, re-meshed as a closed surface.
// Repair's route for open, non-manifold and self-intersecting files (docs/MESHES.md, "Mesh
// repair"): the existing surface is kept where it bounds that region, within the cell size.
#include "geometry/trimesh.hpp"

namespace mesh::detail {

// Volumes of a soup's winding number, sampled at the centres of cells (`cells` along the bounding
// box's longest side).
struct WindingSurvey {
  // Volume where the winding number lies between ¼ and ¾ [m³]: neither clearly inside nor
  // clearly outside (around a hole or an open face), and the box that holds it.
  double ambiguous_volume_m3 = 0.0;
  geometry::Box ambiguous_box;
  double solid_volume_m3 = 0.0;  // volume where the winding number is ≥ ½
  long solid_cells = 0;          // cells it was measured on
};
WindingSurvey survey_winding(const geometry::TriMesh& soup, int cells = 96);

// Parts of an assembly that touch leave between their faces only what their faceting leaves:
// the toothed pulley of the shared dies (a cycloidal drive of 100 shells) holds pins of 1.5875 mm
// radius, 31-gons, in bores of the same radius, 34-gons, at most 5.5 µm apart (all 660 such
// slivers of the file within 0.03 mm), while its designed clearances are 0.397 mm. Outside of
// the solid that a segment this long spans from solid to solid (crossed squarely through its
// middle: up to half of it from a face; on cells under 0.4 mm, shorter, as in_contact_sliver
// says) is such a contact, which the model means as solid
// throughout, not a gap (docs/MESHES.md, "Mesh repair"); a die wall 0.15 mm thick is no contact.
constexpr double contact_gap_m = 0.1e-3;

struct WindingSolid {
  // Closed, outward, crossing nowhere (else folded_at says where); empty when the region is
  // empty or could not be closed.
  geometry::TriMesh mesh;
  // Largest distance from the input's bounding surface (points whose two sides the winding
  // number puts on different sides of ½) to the result [m]: how far the re-meshing moved it.
  double moved_m = 0.0;
  // Terms (WindingNumber::terms) signing the distance band would have summed, where that was
  // more than allowed: the mesh is empty then.
  double refused_terms = 0.0;
  geometry::Vec3 moved_most_at = geometry::Vec3::Zero();  // the input point `moved_m` was measured at [m]
  // Faces of closable gaps the result closed, not counted in `moved_m`: the farthest such
  // point's distance from the result [m], exact where it exceeds `moved_m` (else at most that),
  // and the point.
  double gap_closed_m = 0.0;
  geometry::Vec3 gap_closed_at = geometry::Vec3::Zero();
  // Faces of parts in contact (an assembly's, apart by their faceting alone), which the result
  // joins, not counted in `moved_m` either: the farthest such point from the result [m], and it.
  double contact_joined_m = 0.0;
  geometry::Vec3 contact_joined_at = geometry::Vec3::Zero();
  // Whether the solid at `moved_most_at` is thinner than the closable diameter: the re-mesh
  // joined two parts of the free space across it (a die wall between two cavities).
  bool moved_across_thin_solid = false;
  // Corners of triangles that cross others or are degenerate [m]: empty, unless OpenVDB's zero
  // surface crossed itself there (repair refuses the mesh then).
  std::vector<geometry::Vec3> folded_at;
};

// The free space (where grains move: the solid's inside for a cavity or a container, its outside
// for a tool) a re-mesh may close where no grain of diameter `closable_m` touches the surface.
struct ClosableGaps {
  double closable_m = 0.0;
  bool free_space_inside = true;
};

// The region of `soup` with winding number ≥ ½, meshed on cells of `cell_m` (OpenVDB: the
// soup's unsigned distance signed by the winding number, then its zero surface), unless
// signing it would sum more than `max_terms` winding-number terms; `gaps` may be closed.
WindingSolid winding_solid(const geometry::TriMesh& soup, double cell_m, const ClosableGaps& gaps, double max_terms);

// Cells `winding_solid` would mesh, about: for refusing a re-mesh too fine to afford.
double winding_solid_cells(double surface_area_m2, double cell_m);

}  // namespace mesh::detail
