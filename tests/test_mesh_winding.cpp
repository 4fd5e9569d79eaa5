// geometry/winding and the repair route it opens: analytic winding numbers, the fast evaluation
// against the exact sum, the ray majority that checks it, and a cracked solid re-meshed without
// moving its surface.
#include <gtest/gtest.h>

#include <random>
#include <tuple>
#include <utility>

#include "core/error.hpp"
#include "geometry/winding.hpp"
#include "mesh/exact.hpp"
#include "mesh/repair.hpp"
#include "mesh/shapes.hpp"
#include "mesh/winding_solid.hpp"
#include "meshes.hpp"

using geometry::Vec3;

namespace {

Vec3 mm(double x, double y, double z) { return 1e-3 * Vec3(x, y, z); }

geometry::TriMesh without_top(geometry::TriMesh box) {
  std::erase_if(box.triangles, [&](const geometry::Triangle& t) {
    return box.vertices[t[0]].z() > 9e-3 && box.vertices[t[1]].z() > 9e-3 && box.vertices[t[2]].z() > 9e-3;
  });
  return box;
}

}  // namespace

TEST(WindingNumber, CountsAClosedSolidOnceInsideAndNeverOutside) {
  const geometry::TriMesh box = test::box_mm(0, 10);
  for (const Vec3& p : {mm(5, 5, 5), mm(0.01, 9.99, 0.01), mm(1, 2, 3)})
    EXPECT_NEAR(geometry::exact_winding_number(box, p), 1.0, 1e-12);
  for (const Vec3& p : {mm(-0.01, 5, 5), mm(20, 20, 20), mm(5, 5, 10.01)})
    EXPECT_NEAR(geometry::exact_winding_number(box, p), 0.0, 1e-12);
  // Two overlapping solids count twice where they overlap.
  EXPECT_NEAR(geometry::exact_winding_number(test::joined(box, test::box_mm(5, 15)), mm(7, 7, 7)), 2.0, 1e-12);
}

TEST(WindingNumber, MeasuresTheSolidAngleOfAnOpenSurface) {
  // A box without its top: from the centre each of the five faces subtends a sixth of the
  // sphere; a point in the missing face's plane sees the open boundary as a half space inside
  // the loop and edge-on outside it.
  const geometry::TriMesh open = without_top(test::box_mm(0, 10));
  ASSERT_EQ(open.triangles.size(), 10u);
  EXPECT_NEAR(geometry::exact_winding_number(open, mm(5, 5, 5)), 5.0 / 6.0, 1e-12);
  EXPECT_NEAR(geometry::exact_winding_number(open, mm(5, 5, 10)), 0.5, 1e-12);
  EXPECT_NEAR(geometry::exact_winding_number(open, mm(3, 7, 10)), 0.5, 1e-12);
  EXPECT_NEAR(geometry::exact_winding_number(open, mm(15, 5, 10)), 0.0, 1e-12);
}

// The independent check of issue 19's sign test counts along each ray every face it crosses.
// Two blocks stacked as an assembly's shells are (the toothed pulley of the shared dies has 100)
// share a face: one leaves the first block where the other enters the second, at the same point.
// Stepping past the nearest hit skipped one of the two: a ray from the upper block down through
// them counted 0 or 2 (here 20 of the 2,000 points were misjudged; on the pulley 274 of 10⁵,
// against the file's winding number). Counting every hit, the majority of 7 rays is the winding
// number's verdict at every point.
TEST(ExactSurface, RayMajorityCountsTheCoincidentFacesOfTouchingShells) {
  const geometry::TriMesh stack =
      test::joined(mesh::box_solid(mm(0, 0, 0), mm(10, 10, 10)), mesh::box_solid(mm(0, 0, 10), mm(10, 10, 11)));
  const mesh::ExactSurface rays(stack);
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> across(-1e-3, 11e-3), up(9e-3, 12e-3);
  int wrong = 0, inside = 0;
  for (int n = 0; n < 2000; ++n) {
    const Vec3 p(across(random), across(random), up(random));
    const bool by_winding = geometry::exact_winding_number(stack, p) >= 0.5;
    inside += by_winding;
    wrong += rays.inside_by_ray_majority(p, 7) != by_winding;
  }
  EXPECT_GT(inside, 500);
  EXPECT_EQ(wrong, 0);
}

TEST(WindingNumber, FastEvaluationClassifiesAsTheExactSum) {
  // A ring cavity of a few thousand triangles: the tree's far clusters are dipoles. Points a
  // hundredth of the ring's size or more from its surface are never classified differently.
  const geometry::TriMesh ring = mesh::ring_cavity(30e-3, 12e-3, 10e-3, 2e-6);
  ASSERT_GT(ring.triangles.size(), 1000u);
  const geometry::WindingNumber fast(ring);
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> across(-20e-3, 20e-3), down(-15e-3, 5e-3);
  int compared = 0;
  while (compared < 2000) {
    const Vec3 p(across(random), across(random), down(random));
    const double radius = std::hypot(p.x(), p.y());
    const double clearance = std::min({std::abs(radius - 15e-3), std::abs(radius - 6e-3), std::abs(p.z()),
                                       std::abs(p.z() + 10e-3)});
    if (clearance < 0.3e-3) continue;
    const double exact = geometry::exact_winding_number(ring, p);
    const bool inside = radius > 6e-3 && radius < 15e-3 && p.z() < 0 && p.z() > -10e-3;
    ASSERT_NEAR(exact, inside ? 1.0 : 0.0, 1e-9) << p.transpose();
    ASSERT_EQ(fast(p) >= 0.5, inside) << p.transpose() << " exact " << exact << " fast " << fast(p);
    ++compared;
  }
}

TEST(Repair, ClosesACrackByTheWindingNumberWithinTheTolerance) {
  // The top face lifted 0.05 mm off the walls, unwelded: a crack all round, its loops 10 mm
  // across (too wide to fill as holes), enclosing an evident 10 x 10 x 10.05 mm solid.
  const geometry::TriMesh box = test::box_mm(0, 10);
  geometry::TriMesh top;
  top.vertices = {mm(0, 0, 10.05), mm(10, 0, 10.05), mm(10, 10, 10.05), mm(0, 10, 10.05)};
  top.triangles = {{0, 1, 2}, {0, 2, 3}};
  mesh::RepairOptions options;
  options.tolerance_m = 0.2e-3;
  options.max_hole_m = 2e-3;
  const mesh::RepairResult r = mesh::repair(test::joined(without_top(box), top), options, "cracked.stl");
  EXPECT_TRUE(r.after.closed);
  EXPECT_EQ(r.after.self_intersections, 0u);
  EXPECT_FALSE(r.wrapped);
  ASSERT_TRUE(r.winding_moved_m.has_value());
  EXPECT_LE(r.hausdorff_m, options.tolerance_m);
  // Re-meshing on cells of the tolerance h, with every vertex moved onto the input, can cut
  // each edge of the box by at most a right triangle of legs h: 120 mm of edges x h²/2.
  const double h = options.tolerance_m;
  EXPECT_NEAR(r.after.volume_m3, 10e-3 * 10e-3 * 10.05e-3, 120e-3 * h * h / 2);
  // The top face stays flat at its height: the die's opening is found on it.
  EXPECT_NEAR(r.after.bbox.hi.z(), 10.05e-3, 1e-9);
}

TEST(Repair, NamesTheRegionWhereTheEnclosedVolumeIsUndefined) {
  try {
    mesh::RepairOptions options;
    options.tolerance_m = 0.1e-3;
    mesh::repair(without_top(test::box_mm(0, 10)), options, "open.stl");
    FAIL() << "an open box has no enclosed volume";
  } catch (const diefill::InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.field(), "boundary edges");
    EXPECT_NE(what.find("undefined"), std::string::npos) << what;
    // Around the missing top: the region reaches its plane, z = 10 mm.
    EXPECT_NE(what.find("10] mm"), std::string::npos) << what;
  }
}

// The survey skips blocks of cells where the winding number is clearly on one side; cell by
// cell, every cell's centre read exactly, it must count the same: solid cells, ambiguous cells
// and their box, on an open box (the winding number drifts through ½ around its opening), two
// overlapping boxes (2 where they overlap) and a box with a post and a missing wall.
TEST(WindingSurvey, CountsAsEveryCellReadOneByOne) {
  const geometry::TriMesh die = test::joined(test::box_mm(0, 10), test::reversed(mesh::box_solid(mm(3, 3, 0), mm(7, 7, 4))));
  geometry::TriMesh missing_wall = die;
  std::erase_if(missing_wall.triangles, [&](const geometry::Triangle& t) {
    return missing_wall.vertices[t[0]].x() < 1e-6 && missing_wall.vertices[t[1]].x() < 1e-6 && missing_wall.vertices[t[2]].x() < 1e-6;
  });
  for (const geometry::TriMesh& soup : {without_top(test::box_mm(0, 10)), test::joined(test::box_mm(0, 10), test::box_mm(5, 15)), missing_wall}) {
    // 48 cells along the longest side (the repair's 96 read one by one are slow under the sanitizers).
    const mesh::detail::WindingSurvey survey = mesh::detail::survey_winding(soup, 48);
    const geometry::WindingNumber winding(soup);
    const geometry::Box box = geometry::bounding_box(soup);
    const double h = box.size().maxCoeff() / 48;
    const Eigen::Vector3i n = (box.size() / h).array().ceil().cast<int>().max(1);
    long solid = 0, ambiguous = 0;
    geometry::Box ambiguous_box;
    for (int k = 0; k < n.z(); ++k)
      for (int j = 0; j < n.y(); ++j)
        for (int i = 0; i < n.x(); ++i) {
          const Vec3 p = box.lo + h * Vec3(i + 0.5, j + 0.5, k + 0.5);
          const double w = winding(p);
          solid += w >= 0.5;
          if (w > 0.25 && w < 0.75) {
            ++ambiguous;
            ambiguous_box.extend(p - Vec3::Constant(0.5 * h));
            ambiguous_box.extend(p + Vec3::Constant(0.5 * h));
          }
        }
    EXPECT_EQ(survey.solid_cells, solid);
    EXPECT_NEAR(survey.ambiguous_volume_m3, double(ambiguous) * h * h * h, 1e-9 * double(ambiguous) * h * h * h);
    if (ambiguous > 0) {
      EXPECT_LT((survey.ambiguous_box.lo - ambiguous_box.lo).norm(), 1e-6 * h);
      EXPECT_LT((survey.ambiguous_box.hi - ambiguous_box.hi).norm(), 1e-6 * h);
    }
    EXPECT_GT(solid, 0);
  }
}

// The re-mesh's samples lie 0.159 mm (1/π of a cell) off multiples of its 0.5 mm cells: none in
// a gap from x = 10 to 10.15 mm between two blocks (wider than the quarter cell off a face at
// which what bounds the solid is told) or in a plate 0.2 mm thick around z = 5 mm. The re-mesh
// fills the gap and drops the plate. Either is free space no grain 0.5 mm
// across touches: a gap between the blocks of a tool, a thin slot of a cavity; for the other
// role it is the solid, and losing it moves the surface. The faces left 5 mm from the result
// are the gap's middle (5 mm from the sides of the block the two become) and the plate's tip
// (5 mm from the block it stood out of).
TEST(WindingSolid, ClosesOnlyFreeSpaceNoGrainOfTheClosableDiameterTouches) {
  const double cell = 0.5e-3;
  const geometry::TriMesh gap = test::joined(test::box_mm(0, 10), mesh::box_solid(mm(10.15, 0, 0), mm(20, 10, 10)));
  const geometry::TriMesh plate = test::joined(test::box_mm(0, 10), mesh::box_solid(mm(10, 0, 4.9), mm(15, 10, 5.1)));
  const mesh::detail::ClosableGaps tool{cell, false}, cavity{cell, true};
  for (const auto& [soup, free_space, other_role] : {std::tuple{gap, tool, cavity}, std::tuple{plate, cavity, tool}}) {
    const mesh::detail::WindingSolid closed = mesh::detail::winding_solid(soup, cell, free_space, 2e9);
    EXPECT_LE(closed.moved_m, cell) << closed.moved_most_at.transpose() * 1e3;
    EXPECT_NEAR(closed.gap_closed_m, 5e-3, cell);
    const mesh::detail::WindingSolid kept = mesh::detail::winding_solid(soup, cell, other_role, 2e9);
    EXPECT_NEAR(kept.moved_m, 5e-3, cell);
  }
}

// An assembly's parts in contact: two blocks standing on a base (itself two blocks side by
// side), their facing sides 0.02 mm apart, under half of `contact_gap_m`, as touching parts are by
// their faceting alone. The slit's floor, the base's top between them, bounds the solid in the
// file; for a cavity the slit is a die wall between two parts of it, which cells of 0.5 mm
// remove. Its faces are joined as parts in contact: none counts as moved, and the farthest, the
// floor's middle, lies 5 mm inside the block they make. A slit of 0.15 mm is a die wall: counted,
// moved 5 mm, as before.
TEST(WindingSolid, JoinsPartsInContactAcrossTheSliverTheirFacetingLeaves) {
  const double cell = 0.5e-3;
  const geometry::TriMesh base = test::joined(mesh::box_solid(mm(0, 0, 0), mm(5, 10, 5)), mesh::box_solid(mm(5, 0, 0), mm(10, 10, 5)));
  for (const auto& [slit_mm, in_contact] : {std::pair{0.02, true}, std::pair{0.15, false}}) {
    SCOPED_TRACE(slit_mm);
    const double half = 0.5 * slit_mm;
    const geometry::TriMesh soup = test::joined(base, test::joined(mesh::box_solid(mm(0, 0, 5), mm(5 - half, 10, 10)),
                                                                   mesh::box_solid(mm(5 + half, 0, 5), mm(10, 10, 10))));
    const mesh::detail::WindingSolid solid = mesh::detail::winding_solid(soup, cell, {cell, true}, 2e9);
    if (in_contact) {
      EXPECT_LE(solid.moved_m, cell) << solid.moved_most_at.transpose() * 1e3;
      EXPECT_NEAR(solid.contact_joined_m, 5e-3, cell) << solid.contact_joined_at.transpose() * 1e3;
    } else {
      EXPECT_NEAR(solid.moved_m, 5e-3, cell) << solid.moved_most_at.transpose() * 1e3;
      EXPECT_EQ(solid.contact_joined_m, 0.0);
    }
  }
}

// The same gap beside a cracked block (which takes repair to the winding-number solid): for a tool
// repair closes it and says so; for a cavity it is a die wall 0.15 mm thick between two parts of
// the cavity, which the cells would remove, and repair refuses, saying so and naming die.part.
TEST(Repair, ClosesAGapNoGrainTouchesForAToolAndRefusesToJoinACavityAcrossAThinWall) {
  geometry::TriMesh top;
  top.vertices = {mm(0, 0, 10.05), mm(10, 0, 10.05), mm(10, 10, 10.05), mm(0, 10, 10.05)};
  top.triangles = {{0, 1, 2}, {0, 2, 3}};
  const geometry::TriMesh soup = test::joined(test::joined(without_top(test::box_mm(0, 10)), top),
                                              mesh::box_solid(mm(10.15, 0, 0), mm(20, 10, 10)));
  mesh::RepairOptions options;
  options.tolerance_m = 0.5e-3;
  options.max_hole_m = 2e-3;
  options.closable_gap_m = 0.5e-3;
  options.free_space_inside = false;
  const mesh::RepairResult tool = mesh::repair(soup, options, "blocks.stl");
  EXPECT_LE(tool.hausdorff_m, options.tolerance_m);
  EXPECT_EQ(tool.after.shells, 1u);
  EXPECT_NE(::testing::PrintToString(tool.actions).find("closed gaps of the free space no grain 0.5 mm across"),
            std::string::npos)
      << ::testing::PrintToString(tool.actions);
  options.free_space_inside = true;
  try {
    mesh::repair(soup, options, "blocks.stl");
    FAIL() << "a cavity joined across its wall";
  } catch (const diefill::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("where the die's wall between two parts of the cavity is thinner than 0.5 mm"),
              std::string::npos)
        << e.what();
    // Its separate shells may be an assembly's parts, each a die of its own (docs/MESHES.md, "Assemblies").
    EXPECT_NE(std::string(e.what()).find("die.part"), std::string::npos) << e.what();
  }
}
