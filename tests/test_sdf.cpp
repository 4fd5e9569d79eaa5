// mesh/sdf and geometry/wall_field against the exact Embree distance on the bundled dies; the cache.
#include <gtest/gtest.h>

#include <random>

#include "mesh/die.hpp"
#include "mesh/exact.hpp"
#include "mesh/import.hpp"
#include "mesh/sdf.hpp"
#include "mesh/shapes.hpp"
#include "mesh/tool.hpp"
#include "mesh/verify.hpp"
#include "meshes.hpp"
#include "support.hpp"

using geometry::Vec3;

namespace {

mesh::DieOptions default_options() { return mesh::die_options_for_grains(0.5e-3, 0.25e-3); }

}  // namespace

class SdfOnBundledDie : public ::testing::TestWithParam<std::string> {};

TEST_P(SdfOnBundledDie, MatchesTheExactDistance) {
  const std::string name = GetParam();
  const mesh::PreparedDie die =
      mesh::prepare_die(test::source_dir() / "dies" / (name + ".stl"), default_options(), std::nullopt);
  const mesh::ExactSurface exact(die.solid);
  const geometry::WallField field = die.sdf.wall_field(die.solid);
  const mesh::SdfVerification v = mesh::verify_sdf(field, die.solid, exact, 12000, 7);
  ASSERT_EQ(v.samples, 12000u);
  ASSERT_GE(v.smooth_samples, 10000u);
  // The wall query: within 0.05 voxel everywhere (away from sharp edges, as asked, and near
  // them too), and the exact sign wherever the point is more than half a voxel from the wall.
  EXPECT_LE(v.query.max_smooth_voxels, 0.05) << name;
  EXPECT_LE(v.query.max_voxels, 0.05) << name;
  EXPECT_EQ(v.query.sign_disagreements, 0u) << name;
  // The grid's plain trilinear interpolation keeps the sign; its value error (reported, up to
  // about a quarter voxel on the medial surface of concave edges) is why the query exists.
  EXPECT_EQ(v.grid.sign_disagreements, 0u) << name;
  RecordProperty("trilinear_max_error_voxels", std::to_string(v.grid.max_voxels));
  std::printf("%s: wall query max %.3g voxel; trilinear max %.3g, mean %.3g voxel\n", name.c_str(),
              v.query.max_voxels, v.grid.max_voxels, v.grid.mean_voxels);
}

TEST_P(SdfOnBundledDie, GridNodesHoldExactDistances) {
  const std::string name = GetParam();
  const mesh::PreparedDie die =
      mesh::prepare_die(test::source_dir() / "dies" / (name + ".stl"), default_options(), std::nullopt);
  const mesh::ExactSurface exact(die.solid);
  const double h = die.sdf.voxel_size();
  const std::vector<Vec3> nodes = die.sdf.active_voxel_positions(97);
  ASSERT_GT(nodes.size(), 10000u);
  double worst = 0.0;
  for (const Vec3& p : nodes) worst = std::max(worst, std::abs(die.sdf.sample(p) - exact.signed_distance(p)));
  // Single-precision storage: a few parts in 10^7 of the band width.
  EXPECT_LT(worst / h, 1e-4) << name << " with renormalisation disabled";
}

INSTANTIATE_TEST_SUITE_P(Dies, SdfOnBundledDie, ::testing::Values("ring", "disc"));

// Random samples rarely land where a wrong sign would do harm: beside the sharp edges and corners
// of close cavity features, where the closest feature is an edge or a vertex shared by sliver
// triangles. So the points here sit within 0.8 mm of every vertex of the gear's, the slot's and
// the splined bore's extruded outlines (at the floor, at mid-depth and at the table), as grains of 0.4 mm radius
// touching the walls would; for each farther than half a voxel from the surface, the field's
// sign and every wall contact's sign must be the exact (Embree) one.
class SignAtSharpFeatures : public ::testing::TestWithParam<std::string> {};

TEST_P(SignAtSharpFeatures, IsTheExactSignBesideEveryEdgeAndCorner) {
  const std::string name = GetParam();
  test::TempDir dir;
  const geometry::TriMesh cavity = mesh::bundled_die(name);
  mesh::write_stl(cavity, dir / "die.stl", geometry::LengthUnit::mm, "diefill " + name + " cavity, mm");
  const double r = 0.4e-3;
  const mesh::PreparedDie die = mesh::prepare_die(dir / "die.stl", mesh::die_options_for_grains(r, 0.5 * r), std::nullopt);
  const mesh::ExactSurface exact(die.solid);
  const geometry::WallField field = die.sdf.wall_field(die.solid);
  std::mt19937_64 random(5);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), reach(0.02e-3, 0.8e-3);
  std::size_t checked = 0, field_wrong = 0, contact_wrong = 0;
  Vec3 first_wrong = Vec3::Zero();
  const int per_vertex = std::max(12, int(24000 / cavity.vertices.size()));  // at least 10^4 points in all
  for (const Vec3& v : cavity.vertices) {
    if (v.head<2>().norm() < 1e-9) continue;  // the caps' centres
    for (const double z : {v.z(), -4e-3}) {
      for (int n = 0; n < per_vertex; ++n) {
        Vec3 u(unit(random), unit(random), unit(random));
        if (u.norm() < 1e-3) continue;
        const Vec3 p = Vec3(v.x(), v.y(), z) + reach(random) * u.normalized();
        const double truth = exact.signed_distance(p);
        if (std::abs(truth) < 0.5 * field.voxel) continue;
        ++checked;
        if ((field.signed_distance(p) < 0) != (truth < 0)) {
          if (field_wrong++ == 0) first_wrong = p;
        }
        geometry::SurfacePoint contacts[4];
        const int count = field.local_minima(p, r, contacts, 4);
        for (int c = 0; c < count; ++c) contact_wrong += (contacts[c].distance < 0) != (truth < 0);
      }
    }
  }
  EXPECT_GT(checked, 10000u);
  EXPECT_EQ(field_wrong, 0u) << name << ": first at (" << first_wrong.transpose() * 1e3 << ") mm";
  EXPECT_EQ(contact_wrong, 0u) << name;
  std::printf("%s: %zu points beside edges and corners, %zu signs wrong, %zu contact signs wrong\n", name.c_str(), checked,
              field_wrong, contact_wrong);
}

INSTANTIATE_TEST_SUITE_P(Dies, SignAtSharpFeatures, ::testing::Values("gear", "slot", "spline"));

TEST(Sdf, BandCoversContactRangeAndSkinOnly) {
  const mesh::DieOptions o = default_options();
  const mesh::PreparedDie die = mesh::prepare_die(test::source_dir() / "dies" / "disc.stl", o, std::nullopt);
  const mesh::ExactSurface exact(die.solid);
  double farthest_out = 0.0, farthest_in = 0.0;
  for (const Vec3& p : die.sdf.active_voxel_positions(13)) {
    const double d = exact.signed_distance(p);
    farthest_out = std::max(farthest_out, d);
    farthest_in = std::max(farthest_in, -d);
  }
  EXPECT_GE(farthest_out, 0.5e-3 + 0.25e-3) << "radius plus skin must be in the band";
  EXPECT_LE(farthest_out, o.exterior_band_m + 1e-9);
  EXPECT_LE(farthest_in, o.interior_band_m + 1e-9);
}

// Free space thinner than a voxel inside a solid, here a sealed slab-shaped void 0.15 to 0.7 voxel
// thick (on the toothed pulley of the shared dies, the clearances of its assembly): OpenVDB's
// removal of "self-intersecting" voxels deactivated band voxels beside it, and the flood fill
// signed them from across the wall (with it, 98 to 196 of these voxels were off in each of the
// six cases). Every voxel within 1.5 voxels of the surface holds its exact signed distance.
TEST(Sdf, ASealedVoidThinnerThanAVoxelKeepsTheBandAroundIt) {
  const double h = 1e-3;
  for (const double thickness : {0.15, 0.45, 0.7}) {
    for (const double offset : {0.0, 0.37}) {
      const geometry::TriMesh void_faces =
          mesh::box_solid(Vec3(2e-3, 2e-3, (5 + offset) * h), Vec3(8e-3, 8e-3, (5 + offset + thickness) * h));
      const geometry::TriMesh solid =
          test::joined(mesh::box_solid(Vec3(0, 0, 0), Vec3(10e-3, 10e-3, 10e-3)), test::reversed(void_faces));
      const mesh::SdfGrid sdf = mesh::build_sdf(solid, {h, 1.65 * h, 3 * h, false});
      const mesh::ExactSurface exact(solid);
      int checked = 0, wrong = 0;
      for (int i = -2; i <= 12; ++i)
        for (int j = -2; j <= 12; ++j)
          for (int k = -2; k <= 12; ++k) {
            const Vec3 p = Vec3(i, j, k) * h;
            const double d = exact.distance(p);
            if (d > 1.5 * h || d < 0.02 * h) continue;  // beyond the test; or a sign within rounding
            ++checked;
            wrong += std::abs(sdf.voxel_value(i, j, k) - exact.signed_distance(p)) > 1e-4 * h;
          }
      EXPECT_GT(checked, 1000) << thickness << " voxel thick, offset " << offset;
      EXPECT_EQ(wrong, 0) << thickness << " voxel thick, offset " << offset;
    }
  }
}

TEST(Sdf, CacheIsKeyedByContentAndParameters) {
  test::TempDir dir;
  const auto mesh_path = dir / "die.stl", cache = dir / "cache";
  std::filesystem::copy_file(test::source_dir() / "dies" / "disc.stl", mesh_path);
  const mesh::DieOptions o = default_options();
  const mesh::PreparedDie first = mesh::prepare_die(mesh_path, o, cache);
  EXPECT_FALSE(first.sdf_from_cache);
  const mesh::PreparedDie again = mesh::prepare_die(mesh_path, o, cache);
  EXPECT_TRUE(again.sdf_from_cache);
  EXPECT_EQ(again.sdf.active_voxels(), first.sdf.active_voxels());
  EXPECT_EQ(again.solid.triangles.size(), first.solid.triangles.size());
  EXPECT_EQ(again.sdf.metadata().at("source_sha256"), first.sha256);

  mesh::DieOptions finer = o;
  finer.voxel_m *= 0.9;
  EXPECT_FALSE(mesh::prepare_die(mesh_path, finer, cache).sdf_from_cache) << "changed parameter";

  std::filesystem::copy_file(test::source_dir() / "dies" / "ring.stl", mesh_path,
                             std::filesystem::copy_options::overwrite_existing);
  const mesh::PreparedDie changed = mesh::prepare_die(mesh_path, o, cache);
  EXPECT_FALSE(changed.sdf_from_cache) << "changed mesh, same name";
  EXPECT_NE(changed.cache_key, first.cache_key);
}

TEST(Sdf, CachedGridReadsBackWithMetadata) {
  test::TempDir dir;
  const mesh::PreparedDie die =
      mesh::prepare_die(test::source_dir() / "dies" / "ring.stl", default_options(), std::nullopt);
  die.sdf.write_cache(dir / "ring.vdb");
  const mesh::SdfGrid back = mesh::SdfGrid::read_cache(dir / "ring.vdb");
  EXPECT_EQ(back.active_voxels(), die.sdf.active_voxels());
  EXPECT_DOUBLE_EQ(back.voxel_size(), die.sdf.voxel_size());
  EXPECT_EQ(back.metadata().at("units"), "m");
  EXPECT_EQ(back.metadata().at("role"), "cavity");
  EXPECT_EQ(back.metadata().at("source_sha256"), die.sha256);
  const Vec3 p(7e-3, 1e-3, -2e-3);
  EXPECT_EQ(back.sample(p), die.sdf.sample(p));
}

// The band reaches three voxels into the solid, as OpenVDB's level sets keep: a trilinear sample
// 1.5 voxels inside a face reads the voxel centres on either side of it, up to 2.5 voxels deep
// when the face lies between grid planes, which a band of two voxels left out (they read as the
// band's edge, not the distance).
TEST(Sdf, InteriorBandHoldsATrilinearSampleOneAndAHalfVoxelsDeep) {
  const mesh::DieOptions o = default_options();
  const double top = 10.06e-3;  // between grid planes (the voxel is 0.125 mm)
  const geometry::TriMesh box = mesh::box_solid(Vec3::Zero(), Vec3(10e-3, 10e-3, top));
  const mesh::SdfGrid sdf = mesh::build_sdf(box, {o.voxel_m, o.exterior_band_m, o.interior_band_m, false});
  const geometry::WallField field = sdf.wall_field(box);
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> across(3e-3, 7e-3), depth(1.4, 1.6);
  for (int n = 0; n < 200; ++n) {
    const double d = depth(random) * o.voxel_m;
    const Vec3 p(across(random), across(random), top - d);
    EXPECT_NEAR(field.trilinear(p), -d, 0.01 * o.voxel_m) << "depth " << d / o.voxel_m << " voxels";
  }
}


// A query tracked from the point's previous one (WallField::local_minima_tracked, as the wall
// stage asks it) on a die of slivers: a Ø20 mm disc cavity with 15,708 full-height side quads
// 4 µm wide and caps fanned from the axis, a point moving down a helix 0.2 mm inside the side
// wall into the corner with the floor, a micron a step. At every step the deepest contact is the
// exact distance (CGAL's closest point) within the facets' sagitta (the minima on neighbouring
// facets of the concave side differ by less: which of them is kept may differ), a fresh query
// from the cell's corners finds as many contacts, each within the sagitta, and near the floor
// both faces of the corner are contacts.
TEST(WallQuery, TrackedQueriesOnSliversFindTheExactClosestPointAsFreshOnesDo) {
  const double radius = 10e-3, chord = 2e-10;
  const geometry::TriMesh cavity = mesh::ring_cavity(2 * radius, 0.0, 10e-3, chord);
  const geometry::TriMesh tool = mesh::tool_from_cavity(cavity, mesh::table_around(cavity, 3e-3), "slivers").mesh;
  mesh::SdfOptions o;
  o.voxel_m = 0.125e-3;
  o.exterior_band_m = 8 * o.voxel_m;
  o.interior_band_m = 2 * o.voxel_m;
  const geometry::WallField field = mesh::build_sdf(tool, o).wall_field(tool);
  const mesh::ExactSurface exact(tool);
  const int segments = int(cavity.triangles.size()) / 4;  // two per side quad, one in each cap's fan
  ASSERT_GT(segments, 15000);
  const double sagitta = radius * (1 - std::cos(3.14159265358979 / segments));
  const double range = 0.25e-3, inset = 0.2e-3;
  std::array<int, 3> cell{};
  std::int32_t seeds[8], count = -1;
  int both_faces = 0;
  for (int step = 0; step <= 9000; ++step) {
    const double z = std::max(-2e-3 - 1e-6 * step, -10e-3 + 0.15e-3);
    const double angle = 0.3 * step / 9000.0;
    const Vec3 p((radius - inset) * std::cos(angle), (radius - inset) * std::sin(angle), z);
    if (count < 0 || field.cell_of(p) != cell) {
      cell = field.cell_of(p);
      count = field.cell_candidates(cell, seeds);
    }
    geometry::SurfacePoint tracked[4], fresh[4];
    const int n = field.local_minima_tracked(p, range, seeds, count, tracked, 4);
    const int m = field.local_minima(p, range, fresh, 4);
    ASSERT_GT(n, 0) << "step " << step;
    ASSERT_EQ(n, m) << "step " << step;
    double deepest = tracked[0].distance;
    for (int k = 0; k < n; ++k) {
      deepest = std::min(deepest, tracked[k].distance);
      EXPECT_NEAR(tracked[k].distance, fresh[k].distance, sagitta) << "step " << step;
    }
    EXPECT_NEAR(deepest, exact.signed_distance(p), sagitta) << "step " << step;
    both_faces += n == 2;
  }
  EXPECT_GT(both_faces, 100) << "the corner with the floor was reached";
}
