// Mesh checks and repair with CGAL Polygon Mesh Processing.
#include "mesh/repair.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/stitch_borders.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Surface_mesh.h>
#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <optional>
#include <stdexcept>

#include "core/error.hpp"
#include "core/log.hpp"
#include "core/timer.hpp"
#include "mesh/cgal_ops.hpp"
#include "mesh/cgal_surface_mesh.hpp"
#include "mesh/versions.hpp"
#include "mesh/weld.hpp"
#include "mesh/winding_solid.hpp"

namespace mesh {

namespace {

using Point = detail::CgalPoint;
using detail::SurfaceMesh;
using detail::to_trimesh;
namespace PMP = CGAL::Polygon_mesh_processing;
using diefill::InputError;

Point to_point(const geometry::Vec3& v) { return {v.x(), v.y(), v.z()}; }

double diameter_of_cycle(const SurfaceMesh& sm, SurfaceMesh::Halfedge_index start) {
  geometry::Box box;
  for (auto h : CGAL::halfedges_around_face(start, sm)) {
    const Point& p = sm.point(sm.target(h));
    box.extend(geometry::Vec3(p.x(), p.y(), p.z()));
  }
  return box.size().norm();
}

// Mean thickness 2V/A of a closed surface: a wrap around an open sheet is only about two
// offsets thick, a real solid is many times thicker.
double mean_thickness(const geometry::TriMesh& mesh) {
  double area = 0.0;
  for (const geometry::Triangle& t : mesh.triangles)
    area += 0.5 * (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                      .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]])
                      .norm();
  return area > 0 ? 2.0 * std::abs(geometry::signed_volume(mesh)) / area : 0.0;
}

std::string mm(double metres) { return fmt::format("{:.4g} mm", metres * 1e3); }

// Each edge-connected piece of a consistently oriented soup turned so that it encloses positive
// volume about its own centroid: the winding number counts a piece exported inward as -1.
geometry::TriMesh outward_pieces(SurfaceMesh sm) {
  auto piece = sm.add_property_map<SurfaceMesh::Face_index, std::size_t>("f:piece").first;
  const std::size_t pieces = PMP::connected_components(sm, piece);
  std::vector<geometry::Vec3> sum(pieces, geometry::Vec3::Zero());
  std::vector<double> count(pieces, 0.0), six_volume(pieces, 0.0);
  auto position = [&](SurfaceMesh::Vertex_index v) {
    const Point& p = sm.point(v);
    return geometry::Vec3(p.x(), p.y(), p.z());
  };
  for (auto f : sm.faces())
    for (auto v : CGAL::vertices_around_face(sm.halfedge(f), sm)) sum[piece[f]] += position(v), count[piece[f]] += 1;
  for (auto f : sm.faces()) {
    const geometry::Vec3 centre = sum[piece[f]] / count[piece[f]];
    std::array<geometry::Vec3, 3> corner;
    int k = 0;
    for (auto v : CGAL::vertices_around_face(sm.halfedge(f), sm))
      if (k < 3) corner[std::size_t(k++)] = position(v) - centre;
    six_volume[piece[f]] += corner[0].dot(corner[1].cross(corner[2]));
  }
  geometry::TriMesh out = to_trimesh(sm);
  std::size_t f = 0;
  for (auto face : sm.faces()) {
    if (six_volume[piece[face]] < 0) std::swap(out.triangles[f][1], out.triangles[f][2]);
    ++f;
  }
  return out;
}

// The mesh as the polygon soup CGAL's soup repair takes.
struct Soup {
  std::vector<Point> points;
  std::vector<std::vector<std::size_t>> polygons;
};
Soup soup_of(const geometry::TriMesh& mesh) {
  Soup soup;
  soup.points.reserve(mesh.vertices.size());
  for (const geometry::Vec3& v : mesh.vertices) soup.points.push_back(to_point(v));
  soup.polygons.reserve(mesh.triangles.size());
  for (const geometry::Triangle& t : mesh.triangles)
    soup.polygons.push_back({std::size_t(t[0]), std::size_t(t[1]), std::size_t(t[2])});
  return soup;
}

// The repaired mesh back in CGAL's form: it came out of a Surface_mesh, so it is a polygon mesh.
SurfaceMesh polygon_mesh_of(const geometry::TriMesh& mesh) {
  SurfaceMesh sm;
  if (!detail::to_surface_mesh(mesh, sm)) throw std::logic_error("repair: a repaired surface is not a polygon mesh");
  return sm;
}

// Weld distances tried on a closed surface that crosses itself, as shares of the tolerance: a
// fold this small is a seam of the file (the planetary gear set's ring gear folds in slivers
// 2 µm across where its profile's ends meet, 98 crossing pairs), not a shape; the smallest weld
// that removes every crossing is taken, so that repair moves no more than it must.
constexpr double weld_shares_of_tolerance[] = {1e-3, 1e-2, 1e-1};

// Step 4 of repair, first choice: the surface with vertices closer than a small weld distance
// made one, when that leaves it closed, oriented and free of crossings; else empty.
struct SmallFoldsWelded {
  geometry::TriMesh mesh;
  double distance_m = 0.0;
  double moved_m = 0.0;
  std::size_t merged = 0;
};
std::optional<SmallFoldsWelded> weld_small_folds(const geometry::TriMesh& mesh, double tolerance_m) {
  for (const double share : weld_shares_of_tolerance) {
    const WeldedMesh welded = weld_close_vertices(mesh, share * tolerance_m);
    if (welded.merged == 0) continue;
    auto [points, polygons] = soup_of(welded.mesh);
    PMP::repair_polygon_soup(points, polygons);
    if (!PMP::orient_polygon_soup(points, polygons)) continue;  // the weld pinched the surface
    SurfaceMesh sm;
    PMP::polygon_soup_to_polygon_mesh(points, polygons, sm);
    PMP::remove_degenerate_faces(sm);
    sm.collect_garbage();
    if (!CGAL::is_closed(sm)) continue;
    geometry::TriMesh result = to_trimesh(sm);
    if (detail::count_self_intersections(result) > 0) continue;
    return SmallFoldsWelded{std::move(result), share * tolerance_m, welded.moved_m, welded.merged};
  }
  return std::nullopt;
}

// The winding-number route is refused beyond this much ambiguous volume, as a share of the
// solid: a crack or a small hole leaves a sliver of it, a missing face a region as large as the
// part (docs/MESHES.md, "Mesh repair"). The project's choice, not a published bound.
constexpr double max_ambiguous_share = 0.01;
// Survey cells the solid must fill for its ambiguous share to mean anything: a corrupt vertex
// hundreds of metres away stretches the survey's box until the part sits in a cell or two
// (the mutated dies of test_mesh_fuzz). A ring 100 mm across with walls of 1 mm fills about 2900.
constexpr long min_survey_cells = 1000;
// Distance-band cells beyond which the winding-number re-mesh takes minutes on two cores.
constexpr double max_winding_cells = 1.5e8;
// Winding-number terms (solid angles and dipoles) beyond which signing the distance band takes
// over about half a minute on two cores (1.35·10⁹ terms took 20 s, the open gear of the shared
// dies at cells of 0.0625 mm): counted, not timed, so that the choice is the same on every machine.
constexpr double max_winding_terms = 2e9;

// Alpha wraps beyond this size take minutes on two cores (1.4 million triangles: 250 s); the user is asked to repair
// the mesh or accept a coarser tolerance instead.
constexpr double max_wrap_triangles = 3e5;

// Step 7 of repair, first choice: the solid the surface's winding number encloses, re-meshed on
// cells of the tolerance. Refused by name where that solid is undefined (too much ambiguous
// volume); empty where re-meshing would cost too much or move the surface beyond the tolerance,
// so that the alpha wrap is tried instead.
std::optional<geometry::TriMesh> winding_number_solid(const SurfaceMesh& sm, const MeshReport& before,
                                                      const RepairOptions& options, const std::string& source,
                                                      std::string& defect, RepairResult& result) {
  const double cell = options.tolerance_m;
  if (detail::winding_solid_cells(before.area_m2, cell) > max_winding_cells) return std::nullopt;
  diefill::Stopwatch clock;
  const geometry::TriMesh soup = outward_pieces(sm);
  const detail::WindingSurvey survey = detail::survey_winding(soup);
  if (survey.solid_cells < min_survey_cells) {
    diefill::log::debug("repair: the winding-number survey resolves the solid in {} cells only", survey.solid_cells);
    return std::nullopt;
  }
  if (survey.ambiguous_volume_m3 > max_ambiguous_share * survey.solid_volume_m3) {
    const geometry::Box& b = survey.ambiguous_box;
    throw InputError(source, "boundary edges",
                     fmt::format("{}; the volume it encloses is undefined: its winding number is "
                                 "neither near 0 nor near 1 in {:.4g} mm³ ({:.3g} % of the {:.4g} mm³ it "
                                 "clearly encloses), within [{:.4g}, {:.4g}, {:.4g}] – [{:.4g}, {:.4g}, "
                                 "{:.4g}] mm: an open face or a large hole",
                                 defect, survey.ambiguous_volume_m3 * 1e9,
                                 100 * survey.ambiguous_volume_m3 / survey.solid_volume_m3,
                                 survey.solid_volume_m3 * 1e9, b.lo.x() * 1e3, b.lo.y() * 1e3,
                                 b.lo.z() * 1e3, b.hi.x() * 1e3, b.hi.y() * 1e3, b.hi.z() * 1e3),
                     "Close the mesh in CAD there");
  }
  detail::WindingSolid solid =
      detail::winding_solid(soup, cell, {options.closable_gap_m, options.free_space_inside}, max_winding_terms);
  diefill::log::debug("repair: winding-number solid ({} triangles, moved {}) in {:.2f} s",
                      solid.mesh.triangles.size(), mm(solid.moved_m), clock.seconds());
  if (solid.refused_terms > 0) {
    // The band's voxels, and so the terms, grow as the inverse square of the cell.
    defect += fmt::format("; re-meshing the solid its winding number encloses on cells of {} would sum "
                          "about {:.2g}·10⁹ terms, more than the {:.2g}·10⁹ affordable (a tolerance of about {} would be)",
                          mm(cell), solid.refused_terms / 1e9, max_winding_terms / 1e9,
                          mm(cell * std::sqrt(solid.refused_terms / max_winding_terms)));
    return std::nullopt;
  }
  if (solid.mesh.triangles.empty()) return std::nullopt;
  const auto refused = [&](const std::string& what, const geometry::Vec3& where_m, const std::string& there = "") {
    const geometry::Vec3 at = 1e3 * where_m;
    defect += fmt::format("; re-meshed on cells of {} as the solid its winding number encloses, it would {} at ({:.4g}, "
                          "{:.4g}, {:.4g}) mm{}",
                          mm(cell), what, at.x(), at.y(), at.z(), there);
    return std::nullopt;
  };
  if (!solid.folded_at.empty()) return refused("cross itself", solid.folded_at.front());
  if (solid.moved_m > options.tolerance_m)
    return refused(fmt::format("move the surface by {}", mm(solid.moved_m)), solid.moved_most_at,
                   !solid.moved_across_thin_solid ? ""
                   : fmt::format(", where {} is thinner than {} and the cells join what it parts{}",
                                 options.free_space_inside ? "the die's wall between two parts of the cavity" : "the solid",
                                 mm(options.closable_gap_m),
                                 options.free_space_inside && before.shells > 1
                                     ? " (if its separate shells are an assembly's parts, each needs a die of its own: "
                                       "die.part, or diefill sdf --part, chooses one)"
                                     : ""));
  result.actions.push_back(fmt::format(
      "{}: re-meshed as the solid its winding number encloses (cells of {}; ambiguous volume {:.4g} mm³, "
      "{:.3g} % of the solid)",
      defect, mm(cell), survey.ambiguous_volume_m3 * 1e9, 100 * survey.ambiguous_volume_m3 / survey.solid_volume_m3));
  if (solid.gap_closed_m > solid.moved_m) {
    const geometry::Vec3 at = 1e3 * solid.gap_closed_at;
    result.actions.push_back(fmt::format(
        "closed gaps of the free space no grain {} across can touch the surface in: their faces lie up to {} from "
        "the result, at ({:.4g}, {:.4g}, {:.4g}) mm",
        mm(options.closable_gap_m), mm(solid.gap_closed_m), at.x(), at.y(), at.z()));
  }
  if (solid.contact_joined_m > solid.moved_m) {
    const geometry::Vec3 at = 1e3 * solid.contact_joined_at;
    result.actions.push_back(fmt::format(
        "joined parts in contact (less than {} apart, as an assembly's parts are by their faceting): their faces lie "
        "up to {} inside the result, at ({:.4g}, {:.4g}, {:.4g}) mm",
        mm(detail::contact_gap_m), mm(solid.contact_joined_m), at.x(), at.y(), at.z()));
  }
  result.winding_moved_m = solid.moved_m;
  return std::move(solid.mesh);
}

// Step 7 of repair, second choice: an alpha wrap within the tolerance (CGAL), refused where the
// holes are wider than the wrapping ball, wrapping is not allowed, or it would cost too much.
geometry::TriMesh alpha_wrapped(const geometry::TriMesh& input, const MeshReport& before, const RepairOptions& options,
                                const std::string& source, const std::string& defect, bool closed,
                                double largest_open_hole, RepairResult& result) {
  diefill::Stopwatch clock;
  const double alpha = 2.0 * options.tolerance_m;
  const double offset = 0.25 * options.tolerance_m;
  // A hole wider than the wrapping ball lets the wrap inside: it would return a thin sheet.
  if (!closed && largest_open_hole > 2.0 * alpha)
    throw InputError(source, "boundary edges",
                     defect + fmt::format("; holes larger than {} are not filled",
                                          mm(options.max_hole_m)),
                     "Close the mesh in CAD, or raise the tolerance (--tolerance) or the largest hole to fill (--max-hole)");
  if (!options.allow_wrap)
    throw InputError(source, "surface", defect,
                     "Repair the mesh in CAD, or allow the alpha-wrap fallback");
  // A wrap has about 2 A / alpha² triangles; beyond a few million it takes many minutes.
  const double expected_triangles = 2.0 * before.area_m2 / (alpha * alpha);
  if (expected_triangles > max_wrap_triangles)
    throw InputError(source, "surface",
                     fmt::format("{}, and wrapping it within the tolerance {} would take about "
                                 "{:.3g} million triangles",
                                 defect, mm(options.tolerance_m), expected_triangles / 1e6),
                     "Repair the mesh in CAD, or raise the tolerance (--tolerance)");
  geometry::TriMesh wrapped = detail::alpha_wrap(input, alpha, offset);
  diefill::log::debug("repair: alpha wrap ({} triangles) done at {:.2f} s", wrapped.triangles.size(),
                      clock.seconds());
  if (wrapped.triangles.empty() || mean_thickness(wrapped) < 10.0 * offset)
    throw InputError(source, "boundary edges",
                     defect + "; it does not enclose a volume, and wrapping it within the "
                              "tolerance " + mm(options.tolerance_m) + " gives only a thin sheet",
                     fmt::format("Close the mesh in CAD, or raise the largest hole to fill "
                                 "(--max-hole, now {})",
                                 mm(options.max_hole_m)));
  result.actions.push_back(fmt::format("{}: alpha-wrapped (alpha {}, offset {})", defect,
                                       mm(alpha), mm(offset)));
  result.wrapped = true;
  return wrapped;
}

// A mesh no repair can read as one solid: too few triangles, or a surface inside out.
void refuse_what_no_repair_reads(const MeshReport& before, const std::string& source) {
  if (before.triangles < 4)
    throw InputError(source, "triangles",
                     fmt::format("{} triangle(s) cannot enclose a solid", before.triangles),
                     "Export the closed solid of the part, not a single face");
  // A consistently oriented closed surface whose faces all point inward bounds the space around
  // a solid. Whether the file means that solid or its complement (a cavity exported as the tool
  // around it) cannot be told from the file, and the two give opposite dies: refuse rather than
  // guess. A surface only partly flipped is an export glitch with one evident reading: it is
  // re-oriented below.
  if (before.orientation == "inward")
    throw InputError(source, "orientation",
                     fmt::format("every face points inward: the surface is inside out (signed volume "
                                 "{:.6g} mm³), so it bounds the space around a solid, not the solid",
                                 before.volume_m3 * 1e9),
                     "Reverse the faces' winding in CAD or a mesh tool (MeshLab: Filters > Normals > "
                     "Invert Faces Orientation) and export it again");
}

bool same_mesh(const geometry::TriMesh& a, const geometry::TriMesh& b) { return a.vertices == b.vertices && a.triangles == b.triangles; }

// The surface between repair's steps.
struct Repairing {
  geometry::TriMesh mesh;
  SurfaceMesh sm;  // the same surface in CGAL's form
  bool closed = false;
  bool self_intersecting = false;
  double largest_open_hole = 0.0;
  bool geometry_changed = false;         // holes filled, re-meshed or wrapped: measured against the input
  std::optional<double> union_moved_m;   // set when the shells were united
  std::optional<double> welded_moved_m;  // set when close vertices were welded
};

// Steps 1 to 3 of repair, on the soup and its surface: duplicates, orientation, stitching, holes.
Repairing repaired_surface(const geometry::TriMesh& input, const RepairOptions& options, RepairResult& result) {
  // 1. Soup level: merge duplicate points, drop triangles with repeated vertices, and keep one
  //    of each duplicated triangle (either winding: double-sided surfaces become single).
  auto [points, polygons] = soup_of(input);
  PMP::repair_polygon_soup(points, polygons);
  if (polygons.size() != input.triangles.size())
    result.actions.push_back(fmt::format("removed {} duplicate or repeated-vertex triangles",
                                         input.triangles.size() - polygons.size()));

  // 2. Orient the soup consistently (duplicating non-manifold vertices) and stitch the borders
  //    that only failed to share vertices.
  if (!PMP::orient_polygon_soup(points, polygons))
    result.actions.push_back("split non-manifold vertices to orient the surface");
  Repairing r;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, r.sm);
  PMP::stitch_borders(r.sm);
  PMP::remove_degenerate_faces(r.sm);
  r.sm.collect_garbage();

  // 3. Fill holes up to the allowed diameter.
  std::vector<SurfaceMesh::Halfedge_index> cycles;
  PMP::extract_boundary_cycles(r.sm, std::back_inserter(cycles));
  std::size_t open_holes = 0;
  for (auto h : cycles) {
    const double diameter = diameter_of_cycle(r.sm, h);
    if (diameter <= options.max_hole_m) {
      std::vector<SurfaceMesh::Face_index> patch;
      PMP::triangulate_and_refine_hole(r.sm, h, std::back_inserter(patch), CGAL::Emptyset_iterator());
      ++result.holes_filled;
    } else {
      ++open_holes;
      r.largest_open_hole = std::max(r.largest_open_hole, diameter);
    }
  }
  if (result.holes_filled > 0)
    result.actions.push_back(fmt::format("filled {} hole(s) up to {} across",
                                         result.holes_filled, mm(options.max_hole_m)));
  if (result.before.boundary_edges > 0 && cycles.size() == 0)
    result.actions.push_back("stitched borders that did not share vertices");

  r.mesh = to_trimesh(r.sm);
  r.closed = CGAL::is_closed(r.sm) && open_holes == 0;
  // The crossing test is most of the inspection (13 s on a million triangles): a mesh the soup
  // level left as it was is not tested again, nor inspected again at the end.
  r.self_intersecting =
      r.closed && (same_mesh(r.mesh, input) ? result.before.self_intersections : detail::count_self_intersections(r.mesh)) > 0;
  r.geometry_changed = result.holes_filled > 0;
  return r;
}

// 4. A closed surface folded through itself by less than a thousandth to a tenth of the
//    tolerance: its close vertices welded (the folds of a seam close; moves measured below).
void weld_folds_of_a_seam(Repairing& r, const RepairOptions& options, RepairResult& result) {
  std::optional<SmallFoldsWelded> welded = weld_small_folds(r.mesh, options.tolerance_m);
  if (!welded) return;
  result.actions.push_back(fmt::format("welded {} vertices closer than {} to others, removing {} pairs of "
                                       "intersecting triangles (folds smaller than that), moving them by up to {}",
                                       welded->merged, mm(welded->distance_m), result.before.self_intersections,
                                       mm(welded->moved_m)));
  r.mesh = std::move(welded->mesh);
  r.sm = polygon_mesh_of(r.mesh);
  r.self_intersecting = false;
  r.welded_moved_m = welded->moved_m;
}

// 5. Closed shells that intersect each other or themselves (gears in mesh, engravings on a
//    disc, a folded scan): the union of the solids they enclose. The union itself moves no
//    surface that stays on the outside; removing a fold does, and is measured.
void unite_intersecting_shells(Repairing& r, const RepairOptions& options, RepairResult& result) {
  detail::UnionResult united;
  // A fold removed by moving the surface beyond the tolerance is left to the winding number.
  if (!detail::union_of_shells(r.mesh, united) || united.moved_m > options.tolerance_m) return;
  if (united.empty_shells > 0)
    result.actions.push_back(fmt::format("dropped {} shell(s) enclosing no volume", united.empty_shells));
  result.actions.push_back(fmt::format("united {} intersecting shells (exact corefinement)", result.before.shells));
  if (united.unfolded_shells > 0)
    result.actions.push_back(fmt::format("re-meshed {} shell(s) folded through themselves ({} pairs of "
                                         "intersecting triangles in the input), moving them by up to {}",
                                         united.unfolded_shells, result.before.self_intersections, mm(united.moved_m)));
  r.mesh = std::move(united.mesh);
  r.union_moved_m = united.moved_m;
  r.sm = polygon_mesh_of(r.mesh);
  r.self_intersecting = false;
}

// 6. A closed surface: reject shells nested inside others (internal voids or duplicated offset
//    surfaces are no die), then orient every shell outward.
void orient_closed_shells(Repairing& r, const std::string& source, RepairResult& result) {
  std::vector<std::size_t> nesting;
  auto volume_ids = r.sm.add_property_map<SurfaceMesh::Face_index, std::size_t>("f:vid").first;
  PMP::volume_connected_components(r.sm, volume_ids,
                                   CGAL::parameters::do_orientation_tests(false).nesting_levels(std::ref(nesting)));
  const std::size_t nested =
      std::size_t(std::count_if(nesting.begin(), nesting.end(), [](std::size_t l) { return l > 0; }));
  if (nested > 0)
    throw InputError(source, "shells",
                     fmt::format("{} of {} closed shells lie inside another shell (an internal "
                                 "void or a duplicated surface)",
                                 nested, nesting.size()),
                     "A die cavity or grain must be a solid without voids: remove the inner "
                     "shell(s) in CAD");
  const double volume_before = geometry::signed_volume(r.mesh);
  PMP::orient_to_bound_a_volume(r.sm);
  r.mesh = to_trimesh(r.sm);
  if (geometry::signed_volume(r.mesh) != volume_before || result.before.inconsistent_edges > 0)
    result.actions.push_back("oriented every shell outward");
}

// 7. Still open or self-intersecting: the solid its winding number encloses, else a wrap, unless
//    the holes are beyond what a wrap within the tolerance can close, or either would be too fine
//    to afford.
void solid_of_a_broken_surface(Repairing& r, const geometry::TriMesh& input, const RepairOptions& options,
                               const std::string& source, RepairResult& result) {
  const MeshReport& before = result.before;
  std::string defect = "the mesh is not a closed solid";
  std::vector<std::string> parts;
  if (!r.closed && before.boundary_edges > 0)
    parts.push_back(fmt::format("{} boundary edges, largest remaining hole {} across", before.boundary_edges,
                                mm(r.largest_open_hole)));
  if (before.non_manifold_edges > 0) parts.push_back(fmt::format("{} non-manifold edges", before.non_manifold_edges));
  if (const std::size_t crossing =
          same_mesh(r.mesh, input) ? before.self_intersections : detail::count_self_intersections(r.mesh);
      crossing > 0)
    parts.push_back(fmt::format("{} pairs of intersecting triangles", crossing));
  if (!parts.empty()) defect += " (" + fmt::format("{}", fmt::join(parts, "; ")) + ")";
  if (std::optional<geometry::TriMesh> solid = winding_number_solid(r.sm, before, options, source, defect, result))
    r.mesh = std::move(*solid);
  else
    r.mesh = alpha_wrapped(input, before, options, source, defect, r.closed, r.largest_open_hole, result);
  r.geometry_changed = true;
}

// How far repair moved the existing surface and how wide a gap new surface spans; refused beyond
// the tolerance.
void measure_what_repair_moved(const Repairing& r, const geometry::TriMesh& input, const RepairOptions& options,
                               const std::string& source, RepairResult& result) {
  if (r.welded_moved_m && !r.geometry_changed) {
    // Every point of a welded triangle moved no farther than its corners did: no sampling (the
    // two samplings took 23 s of the planetary gear set's 23.6 s).
    result.hausdorff_m = result.bridged_m = *r.welded_moved_m;
    return;
  }
  if (!r.geometry_changed && !r.union_moved_m) return;
  result.bridged_m = detail::max_distance(r.mesh, input);
  // The union removes faces buried in the solid (a shell inside another, inner lobes), which
  // measured against the result would read as moved by their depth: what it moved is what
  // removing folds moved. Hole patches and a wrap are measured against the input.
  result.hausdorff_m = r.union_moved_m        ? *r.union_moved_m
                       : result.winding_moved_m ? *result.winding_moved_m
                                                : detail::max_distance(input, r.mesh);
  if (result.hausdorff_m > options.tolerance_m)
    throw InputError(source, "tolerance",
                     fmt::format("repair would move the surface by up to {} ({}), more than the "
                                 "tolerance {}",
                                 mm(result.hausdorff_m), result.actions.empty() ? "repair" : result.actions.back(),
                                 mm(options.tolerance_m)),
                     "Repair the mesh in CAD, or raise the tolerance (--tolerance) if that "
                     "change is acceptable");
}

}  // namespace

RepairResult repair(const geometry::TriMesh& input, const RepairOptions& options, const std::string& source) {
  RepairResult result;
  diefill::Stopwatch clock;
  result.before = inspect(input);
  diefill::log::debug("repair: inspected in {:.2f} s", clock.seconds());
  refuse_what_no_repair_reads(result.before, source);

  Repairing r = repaired_surface(input, options, result);
  diefill::log::debug("repair: soup, orientation, stitching and holes done at {:.2f} s", clock.seconds());
  if (r.closed && r.self_intersecting) weld_folds_of_a_seam(r, options, result);
  if (r.closed && r.self_intersecting) {
    unite_intersecting_shells(r, options, result);
    diefill::log::debug("repair: union tried at {:.2f} s", clock.seconds());
  }
  if (r.closed && !r.self_intersecting)
    orient_closed_shells(r, source, result);
  else
    solid_of_a_broken_surface(r, input, options, source, result);
  diefill::log::debug("repair: closed-surface checks done at {:.2f} s", clock.seconds());

  measure_what_repair_moved(r, input, options, source, result);
  result.after = same_mesh(r.mesh, input) ? result.before : inspect(r.mesh);
  result.mesh = std::move(r.mesh);
  result.repaired = !result.actions.empty();
  return result;
}

RepairOptions grain_repair_options(const geometry::TriMesh& grain, double clump_tolerance) {
  const double size = geometry::bounding_box(grain).size().maxCoeff();
  RepairOptions o;
  o.tolerance_m = 0.1 * clump_tolerance * size;
  o.max_hole_m = 0.1 * size;
  return o;
}

std::string format_report(const MeshReport& r) {
  std::string out;
  out += fmt::format("  triangles            {}\n", r.triangles);
  out += fmt::format("  vertices             {}\n", r.vertices);
  out += fmt::format("  shells               {}\n", r.shells);
  out += fmt::format("  boundary edges       {}\n", r.boundary_edges);
  out += fmt::format("  non-manifold edges   {}\n", r.non_manifold_edges);
  out += fmt::format("  inconsistent edges   {}\n", r.inconsistent_edges);
  out += fmt::format("  degenerate faces     {}\n", r.degenerate_faces);
  out += fmt::format("  duplicate faces      {}\n", r.duplicate_faces);
  out += fmt::format("  self-intersections   {}\n", r.self_intersections);
  out += fmt::format("  closed               {}\n", r.closed ? "yes" : "no");
  out += fmt::format("  orientation          {}\n", r.orientation);
  out += fmt::format("  volume               {:.6g} mm³\n", r.volume_m3 * 1e9);
  if (!r.bbox.empty())
    out += fmt::format("  bounding box         [{:.4g}, {:.4g}, {:.4g}] – [{:.4g}, {:.4g}, {:.4g}] mm\n",
                       r.bbox.lo.x() * 1e3, r.bbox.lo.y() * 1e3, r.bbox.lo.z() * 1e3,
                       r.bbox.hi.x() * 1e3, r.bbox.hi.y() * 1e3, r.bbox.hi.z() * 1e3);
  return out;
}

}  // namespace mesh

namespace mesh {
std::string cgal_version() { return CGAL_VERSION_STR; }
}  // namespace mesh
