// Every die mesh of ../shared/data/meshes/dies either loads, repairs and passes the sign check,
// or stops with an error naming its defect. The table is the record of which did which.
#include <gtest/gtest.h>

#include <random>

#include "core/error.hpp"
#include "mesh/die.hpp"
#include "mesh/exact.hpp"
#include "mesh/orientation.hpp"
#include "mesh/verify.hpp"
#include "support.hpp"

namespace {

struct SharedDie {
  const char* file;
  geometry::LengthUnit unit;  // from SOURCES.md: files store none
  const char* defect;     // nullptr: must load; else the error must name this
  // The voxel [mm] for a file whose winding-number solid (docs/MESHES.md, "Mesh repair") is affordable
  // only coarser than 1/300 of the part; such a file's field is also checked against Embree's
  // ray majority on the file as it is (issue 19).
  double voxel_mm = 0;
  // As what it is tested: a tool (the solid itself) unless it is a die the pipeline fills.
  mesh::WallRole role = mesh::WallRole::tool;
  int part = 0;  // one body of an assembly's file (die.part); 0: the whole file
};

// Why each refused mesh is refused, in the words the error must contain.
const SharedDie shared_dies[] = {
    {"blind_flange_disc_trimesh_counter_mm.stl", geometry::LengthUnit::mm, nullptr},         // 6 shells united
    {"stepped_bushing_gazebo_coupling_doublesided.stl", geometry::LengthUnit::mm, nullptr},  // made single-sided
    // No flat face at any extreme: laid flat and cut at its widest section (die.parting), its
    // field's sign checked on the file below the table.
    {"large_turbineblade_vtk_199k.ply", geometry::LengthUnit::mm, nullptr, 0.25, mesh::WallRole::cavity},
    // Slits up to 0.63 mm wide: its winding-number solid costs more than allowed at cells of 0.125 mm
    // (voxels of 0.25 mm, 1/300 of the part); about 0.17 mm is affordable.
    {"flanged_ring_trimesh_idler_riser.stl", geometry::LengthUnit::in, nullptr, 0.4},
    {"gear_8tooth_open_thingi10k_50736.stl", geometry::LengthUnit::mm, nullptr},        // T-junction seams: winding number
    {"sprocket_hub_chrono_m113_singlepin.obj", geometry::LengthUnit::m, nullptr, 2.0},  // open visual mesh
    // Its ring gear folds through itself at a seam, in slivers microns across: welded (see
    // SharedDieCavities below). Tested as the cavity it is: where the teeth of its gears mesh
    // they stand 0.11 to 0.15 mm apart, die walls that the field keeps. (As a tool those gaps are
    // free space narrower than a voxel, where its wall query errs by up to 2 voxels: docs/MESHES.md.)
    {"planetary_gearset_vtk_gears.stl", geometry::LengthUnit::mm, nullptr, 0.714, mesh::WallRole::cavity},
    // 100 overlapping shells: 24·10⁹ winding-number terms at cells of 0.125 mm, and it is refused.
    // At voxels of 0.9 mm it loads as a tool (472 s) and is refused as a cavity (docs/MESHES.md, "Shared
    // dies through the pipeline").
    {"toothed_pulley_hub_trimesh_cycloidal.ply", geometry::LengthUnit::in, "non-manifold edges"},
    // One part of it, as a die is for one part (docs/MESHES.md, "Assemblies"): its 4th largest body, a
    // cycloid disc (43.4 mm across, 3.18 mm thick, lobed, 7 bores), as the cavity it would be.
    {"toothed_pulley_hub_trimesh_cycloidal.ply", geometry::LengthUnit::in, nullptr, 0.15, mesh::WallRole::cavity, 4},
    // 24 crossing shells: as a tool its winding-number solid closes the gaps between them that
    // no grain a voxel across touches, and it loads (as a cavity it has no flat opening).
    {"broken/assimp_3DSMaxExport.stl", geometry::LengthUnit::mm, nullptr},
    {"broken/assimp_Spider_ascii.stl", geometry::LengthUnit::mm, "boundary edges"},
    {"broken/assimp_sphereWithHole.stl", geometry::LengthUnit::mm, nullptr},  // winding number
    {"broken/assimp_triangle_with_two_solids.stl", geometry::LengthUnit::mm, "cannot enclose a solid"},
    {"broken/numpystl_StarWithEmptyHeader.stl", geometry::LengthUnit::mm, nullptr},
    {"broken/trimesh_featuretype_badheader_open.stl", geometry::LengthUnit::in, "boundary edges"},
    {"broken/trimesh_soup.stl", geometry::LengthUnit::mm, "boundary edges"},
    {"broken/trimesh_stl_empty_ascii.stl", geometry::LengthUnit::mm, "not a readable mesh"},
    {"broken/trimesh_stl_empty_bin.stl", geometry::LengthUnit::mm, "not a readable mesh"},
};

void PrintTo(const SharedDie& d, std::ostream* os) { *os << d.file; }

// Issue 19: the field's sign agrees with an independent inside test on the file as it is, not
// on what repair made of it (Embree, the majority of 7 rays in random directions, each counting
// the winding number along it), at 10⁵ random points of the file's box grown by a tenth, those
// farther than one voxel from the file's surface: at least 99.9 %.
// A cavity's field is negative in the die around it: below the table, outside the part (the
// file turned to open upward, as the die is); there points within a voxel of the table, or
// below the part's floor where the die's bottom may be near, are not checked.
void expect_sign_of_the_file(const std::filesystem::path& path, geometry::LengthUnit unit, mesh::WallRole role,
                             const mesh::PreparedDie& die, double voxel) {
  const bool cavity = role == mesh::WallRole::cavity;
  const geometry::TriMesh file = cavity ? mesh::read_die_file(path, unit, die.up, mesh::Parting::automatic, die.part).mesh
                                        : mesh::import_mesh(path, {unit}).mesh;
  const mesh::ExactSurface rays(file);
  const geometry::Box box = geometry::bounding_box(file);
  const geometry::Vec3 margin = 0.1 * box.size();
  std::mt19937_64 random(19);
  std::uniform_real_distribution<double> unit_interval;
  std::size_t checked = 0, agree = 0, inside = 0;
  while (checked < 100000) {
    const geometry::Vec3 p = box.lo - margin + geometry::Vec3(unit_interval(random), unit_interval(random), unit_interval(random))
                                                .cwiseProduct(box.size() + 2 * margin);
    if (rays.distance(p) <= voxel) continue;
    if (cavity && (p.z() < box.lo.z() || p.z() > die.table_z - voxel)) continue;
    ++checked;
    const bool by_rays = rays.inside_by_ray_majority(p, 7);
    inside += by_rays;
    agree += (die.sdf.sample(p) < 0) == (cavity ? !by_rays : by_rays);
  }
  std::printf("%-52s sign: %zu of %zu points agree with the ray majority (%zu inside)\n", path.filename().c_str(), agree,
              checked, inside);
  EXPECT_GE(double(agree), 0.999 * double(checked)) << path;
  EXPECT_GT(inside, checked / 100) << "a test of the solid, not of the space around it";
}

}  // namespace

class SharedDieMesh : public ::testing::TestWithParam<SharedDie> {};

TEST_P(SharedDieMesh, LoadsAndPassesTheSignCheckOrNamesItsDefect) {
  REQUIRE_SHARED_MESHES();
  const SharedDie& d = GetParam();
  const auto path = test::shared_meshes() / "dies" / d.file;
  // A voxel of at least 1/300 of the part keeps the large parts affordable in a test.
  double voxel = d.voxel_mm * 1e-3;
  if (voxel == 0) {
    voxel = 0.125e-3;
    try {
      voxel = std::max(voxel, geometry::bounding_box(mesh::import_mesh(path, {d.unit}).mesh).size().maxCoeff() / 300);
    } catch (const diefill::InputError&) {
      // prepare_die below reports it
    }
  }
  mesh::DieOptions o = mesh::die_options_for_grains(0.5e-3, 0.25e-3, voxel);
  o.unit = d.unit;
  o.role = d.role;
  if (d.defect == nullptr) {
    const mesh::PreparedDie sized = mesh::prepare_die(
        mesh::read_die_file(path, o.unit, mesh::up_to_read(o), mesh::parting_to_read(o), d.part), o, std::nullopt);
    const mesh::ExactSurface exact(sized.solid);
    const mesh::SdfVerification v =
        mesh::verify_sdf(sized.sdf.wall_field(sized.solid), sized.solid, exact, 3000, 3);
    // Repair's contract (mesh/repair.hpp), which the winding-number re-mesh broke on the flanged
    // ring (12,440 crossing pairs, 6,685 degenerate faces) until its samples left round coordinates.
    EXPECT_EQ(sized.after.self_intersections, 0u) << d.file;
    EXPECT_EQ(sized.after.degenerate_faces, 0u) << d.file;
    EXPECT_EQ(v.samples, 3000u) << d.file;
    EXPECT_EQ(v.query.sign_disagreements, 0u) << d.file;
    EXPECT_LE(v.query.max_smooth_voxels, 0.05) << d.file << " at " << v.query.worst_smooth_point.transpose() * 1e3
                                               << " mm, voxel " << voxel * 1e3 << " mm";
    std::printf("%-52s loads: %zu triangles, repairs: %zu, query max error %.2g voxel\n", d.file,
                sized.after.triangles, sized.actions.size(), v.query.max_voxels);
    if (d.voxel_mm > 0) expect_sign_of_the_file(path, d.unit, d.role, sized, voxel);
  } else {
    try {
      mesh::prepare_die(path, o, std::nullopt);
      ADD_FAILURE() << d.file << " was accepted; expected an error naming " << d.defect;
    } catch (const diefill::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(d.defect), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(d.file), std::string::npos) << e.what();
      std::printf("%-52s refused: %.160s\n", d.file, e.what());
    }
  }
}

INSTANTIATE_TEST_SUITE_P(All, SharedDieMesh, ::testing::ValuesIn(shared_dies),
                         [](const ::testing::TestParamInfo<SharedDie>& param_info) {
                           std::string name = param_info.param.file;
                           if (param_info.param.part > 0) name += "_part" + std::to_string(param_info.param.part);
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

// Files store no unit: each die of the folder (not broken/) read with none given is read in the
// unit SOURCES.md judges it to have (docs/MESHES.md, "Units").
TEST(SharedDieUnits, AreGuessedAsTheSourcesJudgeThem) {
  REQUIRE_SHARED_MESHES();
  for (const SharedDie& d : shared_dies) {
    if (std::string_view(d.file).starts_with("broken/")) continue;
    const mesh::ImportResult r = mesh::import_mesh(test::shared_meshes() / "dies" / d.file, {std::nullopt});
    EXPECT_EQ(geometry::unit_name(r.unit), geometry::unit_name(d.unit)) << d.file;
  }
}

// The opening a shoe can pass over, on two shared dies whose top face is a tooth tip (the open
// 8-tooth gear, lying on its side) and a boss (the flanged ring): the gear's side with the larger
// flat face (-y: 235 mm² against 181) and the flange plate's face (-z).
TEST(SharedDieOpenings, AreTheFacesThatOpenTheOutline) {
  REQUIRE_SHARED_MESHES();
  const auto opening = [](const char* file, geometry::LengthUnit unit) {
    return mesh::read_die_file(test::shared_meshes() / "dies" / file, unit, std::nullopt).up;
  };
  EXPECT_EQ(mesh::up_name(opening("gear_8tooth_open_thingi10k_50736.stl", geometry::LengthUnit::mm)), "-y");
  EXPECT_EQ(mesh::up_name(opening("flanged_ring_trimesh_idler_riser.stl", geometry::LengthUnit::in)), "-z");
}

// The planetary gear set's ring gear folds through itself where its profile's two ends meet: 98
// pairs of slivers crossing within 2 µm of each other, at z = 0 and 15 mm. Welding the vertices
// closer than a thousandth of the tolerance removes the folds and moves nothing farther than
// that, so it loads as a cavity with its gears apart: the walls of 0.11 to 0.15 mm between their
// teeth stay, and with them the volume. Before, its winding-number solid joined the gears across
// those walls, moved the surface 0.77 mm, and it was refused (docs/MESHES.md, "Shared dies through the
// pipeline").
TEST(SharedDieCavities, APlanetaryGearSetsSeamFoldsAreWeldedAndItsGearsStayApart) {
  REQUIRE_SHARED_MESHES();
  const mesh::DieFile file =
      mesh::read_die_file(test::shared_meshes() / "dies" / "planetary_gearset_vtk_gears.stl", geometry::LengthUnit::mm, std::nullopt);
  EXPECT_EQ(mesh::up_name(file.up), "+z");
  const mesh::RepairOptions o = mesh::die_options_for_grains(0.65e-3, 0.25e-3, 0.714e-3).repair;
  const mesh::RepairResult r = mesh::repair(file.mesh, o, file.source);
  EXPECT_EQ(r.before.self_intersections, 98u);
  EXPECT_EQ(r.after.self_intersections, 0u);
  EXPECT_EQ(r.after.shells, 7u) << "the sun, the five planets and the ring gear, each its own";
  ASSERT_EQ(r.actions.size(), 1u);
  EXPECT_NE(r.actions.front().find("welded"), std::string::npos) << r.actions.front();
  EXPECT_LE(r.hausdorff_m, 1e-3 * o.tolerance_m);
  const double volume = geometry::signed_volume(file.mesh);
  EXPECT_NEAR(r.after.volume_m3, volume, 1e-6 * volume);
}

// Where the cell's candidate triangles miss the closest one: on the flange disc, 0.53 mm inside
// the solid at 1.01 mm voxels, the descents from the cell's eight candidates end on faces of
// both signs and the nearest of them (+0.531 mm) was the wrong one. Candidates that disagree in
// sign now widen the search to the 3x3x3 voxels, which finds the true closest triangle.
TEST(WallQuery, MinimaOfBothSignsWidenTheSearchToTheTrueClosestTriangle) {
  REQUIRE_SHARED_MESHES();
  mesh::DieOptions o = mesh::die_options_for_grains(0.5e-3, 0.25e-3, 1.0133e-3);
  o.role = mesh::WallRole::tool;
  const mesh::PreparedDie die =
      mesh::prepare_die(test::shared_meshes() / "dies" / "blind_flange_disc_trimesh_counter_mm.stl", o, std::nullopt);
  const geometry::WallField field = die.sdf.wall_field(die.solid);
  const mesh::ExactSurface exact(die.solid);
  const geometry::Vec3 p(174.9516e-3, 204.3411e-3, 279.0145e-3);
  EXPECT_NEAR(exact.signed_distance(p), -0.5277e-3, 1e-7);
  EXPECT_NEAR(field.signed_distance(p), exact.signed_distance(p), 1e-12);
  geometry::SurfacePoint contacts[4];
  const int n = field.local_minima(p, 1e-3, contacts, 4);
  ASSERT_GT(n, 0);
  for (int k = 0; k < n; ++k) EXPECT_LT(contacts[k].distance, 0) << "a point inside is inside for every contact";
}

// Beside a sheet thinner than a voxel: on the flange disc at 0.2 mm voxels two faces lie back to
// back microns apart, and every candidate triangle within reach leads to the one these points lie
// behind (they were 0.1669 and 0.1461 mm "inside") while the exact closest face, 0.5 to 2 µm
// nearer, faces them: they are outside. `diefill sdf --verify` found them beside the sharp edges
// (3 of 50,000 points there). The grid's sign, outside by more than half a voxel, now wins.
TEST(WallQuery, APointBesideASheetThinnerThanAVoxelIsOutside) {
  REQUIRE_SHARED_MESHES();
  mesh::DieOptions o = mesh::die_options_for_grains(0.5e-3, 0.25e-3, 0.2e-3);
  const mesh::PreparedDie die =
      mesh::prepare_die(test::shared_meshes() / "dies" / "blind_flange_disc_trimesh_counter_mm.stl", o, std::nullopt);
  const geometry::WallField field = die.sdf.wall_field(die.solid);
  const mesh::ExactSurface exact(die.solid);
  for (const geometry::Vec3& p : {geometry::Vec3(-44.6740e-3, 46.9778e-3, 279.1630e-3), geometry::Vec3(119.6250e-3, 40.9364e-3, 280.5783e-3)}) {
    const double truth = exact.signed_distance(p);
    ASSERT_GT(truth, 0.5 * field.voxel) << p.transpose() * 1e3;
    EXPECT_NEAR(field.signed_distance(p), truth, 0.01 * field.voxel) << p.transpose() * 1e3;
    geometry::SurfacePoint contacts[4];
    const int n = field.local_minima(p, 0.5e-3, contacts, 4);
    ASSERT_GT(n, 0);
    for (int k = 0; k < n; ++k) EXPECT_GT(contacts[k].distance, 0) << "every contact of a point outside is outside";
  }
}
