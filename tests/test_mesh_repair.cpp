// mesh/repair and mesh/tool: what the checks count, what repair changes, what it refuses.
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "mesh/import.hpp"
#include "mesh/repair.hpp"
#include "mesh/shapes.hpp"
#include "mesh/tool.hpp"
#include "mesh/weld.hpp"
#include "meshes.hpp"

using geometry::Vec3;

namespace {

mesh::RepairOptions options_mm(double tolerance_mm = 0.05, double max_hole_mm = 2.0) {
  mesh::RepairOptions o;
  o.tolerance_m = tolerance_mm * 1e-3;
  o.max_hole_m = max_hole_mm * 1e-3;
  return o;
}

std::string repair_error(const geometry::TriMesh& m, const mesh::RepairOptions& o = options_mm()) {
  try {
    mesh::repair(m, o, "part.stl");
  } catch (const diefill::InputError& e) {
    return e.field() + " | " + e.what();
  }
  return "";
}

}  // namespace

TEST(Inspect, CountsDefects) {
  geometry::TriMesh box = test::box_mm(0, 10);
  const mesh::MeshReport clean = mesh::inspect(box);
  EXPECT_TRUE(clean.closed);
  EXPECT_EQ(clean.orientation, "outward");
  EXPECT_EQ(clean.shells, 1u);
  EXPECT_EQ(clean.self_intersections, 0u);
  EXPECT_NEAR(clean.volume_m3, 1e-6, 1e-15);
  EXPECT_NEAR(clean.area_m2, 6e-4, 1e-15);

  geometry::TriMesh open = box;
  open.triangles.pop_back();
  EXPECT_EQ(mesh::inspect(open).boundary_edges, 3u);
  EXPECT_FALSE(mesh::inspect(open).closed);

  geometry::TriMesh flipped_face = box;
  std::swap(flipped_face.triangles[0][1], flipped_face.triangles[0][2]);
  EXPECT_EQ(mesh::inspect(flipped_face).inconsistent_edges, 3u);
  EXPECT_EQ(mesh::inspect(flipped_face).orientation, "inconsistent");

  geometry::TriMesh fin = box;  // a third triangle on a box edge: non-manifold
  fin.vertices.emplace_back(-5e-3, -5e-3, 5e-3);
  fin.triangles.push_back({0, 1, 8});
  EXPECT_EQ(mesh::inspect(fin).non_manifold_edges, 1u);

  geometry::TriMesh sliver = box;  // zero area: collinear points, and a repeated index
  sliver.vertices.emplace_back(5e-3, 0, 0);
  sliver.triangles.push_back({0, 8, 1});
  sliver.triangles.push_back({0, 0, 1});
  EXPECT_EQ(mesh::inspect(sliver).degenerate_faces, 2u);

  const geometry::TriMesh overlapping = test::joined(box, test::box_mm(5, 15));
  EXPECT_EQ(mesh::inspect(overlapping).shells, 2u);
  EXPECT_GT(mesh::inspect(overlapping).self_intersections, 0u);
  geometry::TriMesh twice = test::joined(box, box);
  mesh::weld_exact(twice);
  EXPECT_EQ(mesh::inspect(twice).duplicate_faces, 12u);
}

TEST(Repair, LeavesACleanSolidAlone) {
  const mesh::RepairResult r = mesh::repair(test::box_mm(0, 10), options_mm(), "box.stl");
  EXPECT_FALSE(r.repaired);
  EXPECT_TRUE(r.actions.empty());
  EXPECT_EQ(r.hausdorff_m, 0.0);
}

TEST(Repair, OrientsPartlyFlippedFacesOutward) {
  // Half the faces reversed: the surface has one evident outside, whichever half was wrong.
  geometry::TriMesh box = test::box_mm(0, 10);
  for (std::size_t f = 0; f < box.triangles.size(); f += 2) std::swap(box.triangles[f][1], box.triangles[f][2]);
  const mesh::RepairResult r = mesh::repair(box, options_mm(), "box.stl");
  EXPECT_EQ(r.before.orientation, "inconsistent");
  EXPECT_EQ(r.after.orientation, "outward");
  EXPECT_NEAR(r.after.volume_m3, 1e-6, 1e-15);
  EXPECT_TRUE(r.repaired);
}

TEST(Repair, RefusesASurfaceTurnedInsideOut) {
  // Every face inward: the file bounds the space around the box; which side is meant is a guess.
  const std::string error = repair_error(test::reversed(test::box_mm(0, 10)));
  EXPECT_EQ(error.rfind("orientation", 0), 0u) << error;
  EXPECT_NE(error.find("inside out"), std::string::npos) << error;
  EXPECT_NE(error.find("Invert Faces"), std::string::npos) << error;
}

TEST(Repair, MakesDoubleSidedSurfacesSingle) {
  const geometry::TriMesh box = test::box_mm(0, 10);
  const mesh::RepairResult r = mesh::repair(test::joined(box, test::reversed(box)), options_mm(), "box.stl");
  EXPECT_EQ(r.after.triangles, 12u);
  EXPECT_NEAR(r.after.volume_m3, 1e-6, 1e-15);
}

TEST(Repair, FillsASmallHoleWithoutMovingTheSurface) {
  // A 10 mm box whose top is split finely, one small triangle missing.
  geometry::TriMesh m = test::box_mm(0, 10);
  m.triangles.pop_back();  // a whole half face: 14 mm across, larger than max_hole
  EXPECT_EQ(repair_error(m).rfind("boundary edges", 0), 0u) << repair_error(m);
  const mesh::RepairResult r = mesh::repair(m, options_mm(0.05, 20.0), "box.stl");
  EXPECT_EQ(r.holes_filled, 1u);
  EXPECT_TRUE(r.after.closed);
  EXPECT_NEAR(r.after.volume_m3, 1e-6, 1e-15);
  EXPECT_LT(r.hausdorff_m, 1e-12) << "the existing surface does not move";
  // The point of the missing triangle farthest from the rest is its incentre, an inradius away.
  EXPECT_NEAR(r.bridged_m, 10e-3 * (2 - std::sqrt(2.0)) / 2, 0.3e-3) << "the fill spans the missing triangle";
}

TEST(Repair, UnitesIntersectingShellsExactly) {
  const mesh::RepairResult r =
      mesh::repair(test::joined(test::box_mm(0, 10), test::box_mm(5, 15)), options_mm(), "two.stl");
  EXPECT_TRUE(r.after.closed);
  EXPECT_EQ(r.after.self_intersections, 0u);
  EXPECT_EQ(r.after.shells, 1u);
  EXPECT_NEAR(r.after.volume_m3, (1000.0 + 1000.0 - 125.0) * 1e-9, 1e-15);
  EXPECT_FALSE(r.wrapped);
}

// A 10 mm cube whose top front edge runs A -> P -> Q -> B with Q 2 µm behind P, as where the two
// ends of a CAD profile miss each other at a seam: the sliver triangles over P-Q fold back over
// their neighbours, on the top face and on the front one. Welding Q onto P (closer than a tenth of
// the 0.05 mm tolerance) removes the folds and moves nothing farther than 2 µm.
TEST(Repair, WeldsAFoldAtASeamMicronsAcross) {
  const double fold = 2e-6;
  geometry::TriMesh cube;
  cube.vertices = {Vec3(0, 0, 0),        Vec3(10e-3, 0, 0),     Vec3(10e-3, 10e-3, 0),     Vec3(0, 10e-3, 0),
                   Vec3(0, 0, 10e-3),    Vec3(10e-3, 0, 10e-3), Vec3(10e-3, 10e-3, 10e-3), Vec3(0, 10e-3, 10e-3),
                   Vec3(5e-3 + fold / 2, 0, 10e-3), Vec3(5e-3 - fold / 2, 0, 10e-3)};
  enum { Ab, Bb, Cb, Db, A, B, C, D, P, Q };
  cube.triangles = {{Ab, Cb, Bb}, {Ab, Db, Cb},                           // bottom
                    {Db, C, Cb},  {Db, D, C},   {Ab, D, Db}, {Ab, A, D},  // back, left
                    {Bb, Cb, C},  {Bb, C, B},                             // right
                    {A, P, D},    {P, Q, D},    {Q, B, C},   {Q, C, D},   // top, folded over P-Q
                    {Ab, P, A},   {Ab, Q, P},   {Ab, Bb, Q}, {Q, Bb, B}}; // front, folded over P-Q
  const mesh::RepairResult r = mesh::repair(cube, options_mm(), "seam.stl");
  EXPECT_GT(r.before.self_intersections, 0u);
  EXPECT_TRUE(r.after.closed);
  EXPECT_EQ(r.after.self_intersections, 0u);
  ASSERT_FALSE(r.actions.empty());
  EXPECT_NE(r.actions.front().find("welded 1 vertices"), std::string::npos) << r.actions.front();
  EXPECT_NEAR(r.hausdorff_m, fold, 1e-12) << "Q moved onto P, no farther";
  EXPECT_NEAR(r.after.volume_m3, 1e-6, 1e-15);
}

// Welding takes each vertex onto the first one closer than the weld distance, never along a
// chain: of three points 0.6 of it apart in a row, the middle one moves and the last stays.
TEST(Weld, MovesAVertexNoFartherThanTheWeldDistance) {
  const double d = 1e-6;
  const geometry::TriMesh row{{Vec3(0, 0, 0), Vec3(0.6 * d, 0, 0), Vec3(1.2 * d, 0, 0), Vec3(0, 1e-3, 0)},
                              {{0, 1, 3}, {1, 2, 3}}};
  const mesh::WeldedMesh w = mesh::weld_close_vertices(row, d);
  EXPECT_EQ(w.merged, 1u);
  EXPECT_DOUBLE_EQ(w.moved_m, 0.6 * d);
  ASSERT_EQ(w.mesh.triangles.size(), 1u) << "the triangle left with a repeated corner is dropped";
  EXPECT_EQ(w.mesh.triangles[0], (geometry::Triangle{0, 2, 3}));
}

TEST(Repair, RefusesWhatItCannotRepairWithinTolerance) {
  EXPECT_EQ(repair_error(geometry::TriMesh{{Vec3(0, 0, 0), Vec3(1e-3, 0, 0), Vec3(0, 1e-3, 0)}, {{0, 1, 2}}})
                .rfind("triangles", 0),
            0u);
  geometry::TriMesh open_box = test::box_mm(0, 10);
  open_box.triangles.resize(10);  // one face missing
  EXPECT_EQ(repair_error(open_box).rfind("boundary edges", 0), 0u) << repair_error(open_box);
  const geometry::TriMesh nested = test::joined(test::box_mm(0, 10), test::box_mm(2, 8));
  EXPECT_EQ(repair_error(nested).rfind("shells", 0), 0u) << repair_error(nested);
}

TEST(Tool, IsTheTableBlockMinusTheCavity) {
  const geometry::TriMesh ring = mesh::bundled_die("ring");
  const mesh::TableExtent table{-20e-3, -15e-3, 25e-3, 15e-3, 5e-3};
  const mesh::ToolMesh tool = mesh::tool_from_cavity(ring, table, "ring.stl");
  EXPECT_DOUBLE_EQ(tool.table_z, 0.0);
  const double block = 45e-3 * 30e-3 * 15e-3;
  EXPECT_NEAR(geometry::signed_volume(tool.mesh), block - geometry::signed_volume(ring), 1e-15);
  const mesh::MeshReport report = mesh::inspect(tool.mesh);
  EXPECT_TRUE(report.closed);
  EXPECT_EQ(report.orientation, "outward");
  EXPECT_EQ(report.self_intersections, 0u);
  EXPECT_EQ(report.shells, 1u);
  // The core of the ring is a table island: the tool's top includes it.
  EXPECT_THROW(mesh::tool_from_cavity(ring, {-5e-3, -5e-3, 5e-3, 5e-3, 1e-3}, "ring.stl"),
               diefill::InputError);
}
