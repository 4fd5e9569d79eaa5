// mesh/import and mesh/shapes: formats, joining, welding, units, and the bundled dies.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/error.hpp"
#include "mesh/die.hpp"
#include "mesh/import.hpp"
#include "mesh/orientation.hpp"
#include "mesh/repair.hpp"
#include "mesh/shapes.hpp"
#include "meshes.hpp"
#include "support.hpp"

using geometry::Vec3;

namespace {

double polygon_annulus_volume(double ro, double ri, double depth, int n) {
  // A regular n-gon inscribed in a circle of radius r has area n/2 r² sin(2π/n).
  return 0.5 * n * std::sin(2 * std::numbers::pi / n) * (ro * ro - ri * ri) * depth;
}

// The octahedron with vertices ±a x, ±b y, ±c z [m], outward: no flat face anywhere.
geometry::TriMesh octahedron_of(double a, double b, double c) {
  geometry::TriMesh octahedron;
  for (const double half : {a, b, c})
    for (int s : {1, -1}) octahedron.vertices.push_back(s * half * Vec3::Unit(int(octahedron.vertices.size()) / 2));
  octahedron.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  return octahedron;
}

}  // namespace

TEST(BundledDies, MeetChordToleranceAndAnalyticVolume) {
  for (const auto& [name, inner] : {std::pair{"ring", 10e-3}, std::pair{"disc", 0.0}}) {
    const geometry::TriMesh die = mesh::bundled_die(name);
    const int n = mesh::circle_segments(10e-3, 5e-6);
    EXPECT_LT(mesh::chord_error(10e-3, n), 0.01e-3) << name;
    EXPECT_NEAR(geometry::signed_volume(die), polygon_annulus_volume(10e-3, inner / 2, 10e-3, n), 1e-15)
        << name;
    // Chord error measured on the mesh: every edge midpoint at the rim lies within 0.01 mm of
    // the circle it approximates.
    double worst = 0.0;
    for (const auto& t : die.triangles)
      for (int k = 0; k < 3; ++k) {
        const Vec3& a = die.vertices[std::size_t(t[std::size_t(k)])];
        const Vec3& b = die.vertices[std::size_t(t[std::size_t(k + 1) % 3])];
        const double ra = std::hypot(a.x(), a.y()), rb = std::hypot(b.x(), b.y());
        if (std::abs(ra - rb) > 1e-12 || ra < 1e-9 || std::abs(a.z() - b.z()) > 1e-12) continue;
        worst = std::max(worst, ra - std::hypot((a.x() + b.x()) / 2, (a.y() + b.y()) / 2));
      }
    EXPECT_GT(worst, 0.0) << name;
    EXPECT_LT(worst, 0.01e-3) << name;
    const geometry::Box box = geometry::bounding_box(die);
    EXPECT_DOUBLE_EQ(box.hi.z(), 0.0) << name << ": top face on the die table";
    EXPECT_DOUBLE_EQ(box.lo.z(), -10e-3) << name;
  }
}

// A rectangle (r from 3 to 5 mm, z from 0 to 4 mm) turned about the axis is the polygonal annulus
// of that many sides, closed and oriented outward: its divergence-theorem volume is the annulus's
// (negative, or short of it, if a face were flipped or missing).
TEST(RevolvedSolid, IsTheClosedPolygonalAnnulus) {
  const int n = 32;
  const geometry::TriMesh tube = mesh::revolved_solid({{3e-3, 0}, {5e-3, 0}, {5e-3, 4e-3}, {3e-3, 4e-3}}, n);
  EXPECT_NEAR(geometry::signed_volume(tube), polygon_annulus_volume(5e-3, 3e-3, 4e-3, n), 1e-15);
  EXPECT_TRUE(mesh::inspect(tube).closed);
}

TEST(BundledDies, FilesInDiesAreTheGeneratedOnes) {
  test::TempDir dir;
  for (const std::string& name : mesh::bundled_die_names()) {
    const auto regenerated = dir / (name + ".stl");
    mesh::write_stl(mesh::bundled_die(name), regenerated, geometry::LengthUnit::mm,
                    "diefill " + name + " cavity, mm");
    EXPECT_EQ(test::read_text(regenerated), test::read_text(test::source_dir() / "dies" / (name + ".stl")))
        << "dies/" << name << ".stl differs from `diefill die " << name << "`";
  }
}

// The splined bore's hub: its volume is the outer circle's polygon less the core's, times the
// depth (the mesh closes on its outlines), and the core's area is the ISO 14 profile's within the
// chords cut every 3°: a 6 x 11 x 14 spline with 3 mm keys.
TEST(BundledDies, SplinedBoreHasTheProfilesArea) {
  const geometry::TriMesh die = mesh::bundled_die("spline");
  const double depth = 8e-3, r = 5.5e-3, big_r = 7e-3, half = 1.5e-3;
  // ∫ sqrt(a² - y²) dy over |y| < h.
  const auto band = [](double a, double h) { return h * std::sqrt(a * a - h * h) + a * a * std::asin(h / a); };
  const double core = std::numbers::pi * r * r + 6 * (band(big_r, half) - band(r, half));  // the minor circle and six keys
  const double hub = std::numbers::pi * 12e-3 * 12e-3;
  EXPECT_NEAR(geometry::signed_volume(die), (hub - core) * depth, 2e-3 * (hub - core) * depth);
  const geometry::Box box = geometry::bounding_box(die);
  EXPECT_DOUBLE_EQ(box.hi.z(), 0.0);
  EXPECT_NEAR(box.size().x(), 24e-3, 2 * 5e-6);  // the outer circle's chord error, at most 5 µm each side
}

// The disc with a conical floor (its centre 1 mm lower): a cavity with one flat end only, its
// opening, where an extruded part has two alike.
geometry::TriMesh disc_with_one_flat_end() {
  geometry::TriMesh die = mesh::bundled_die("disc");
  for (Vec3& v : die.vertices)
    if (v.head<2>().norm() < 1e-12 && v.z() < 0) v.z() -= 1e-3;
  return die;
}

// A die lying on its side or upside down is found facing each of the six ways, and turned back
// exactly (quarter and half turns only permute and negate coordinates); a proper rotation keeps
// its volume's sign. An extruded part's two alike ends are told apart only by the flag: the
// axis is found, the sign is +. A mesh with no flat face at any extreme is refused by name.
TEST(Orientation, FindsTheOpeningWhicheverWayTheDieFaces) {
  const geometry::TriMesh ring = disc_with_one_flat_end();
  for (int axis = 0; axis < 3; ++axis)
    for (int sign : {1, -1}) {
      const mesh::Up up{axis, sign};
      geometry::TriMesh lying = ring;
      for (int k = 0; k < 3; ++k) mesh::turn_up(lying, up);  // a quarter or half turn's inverse
      EXPECT_EQ(mesh::find_opening(lying, "ring"), up) << mesh::up_name(up);
      EXPECT_NEAR(mesh::opening_area(lying, up), 0.25 * std::numbers::pi * 20e-3 * 20e-3, 1e-3 * 3.2e-4);
      mesh::turn_up(lying, up);
      EXPECT_EQ(lying.vertices, ring.vertices) << mesh::up_name(up);
      EXPECT_DOUBLE_EQ(geometry::signed_volume(lying), geometry::signed_volume(ring));
      geometry::TriMesh extruded = mesh::bundled_die("ring");
      for (int k = 0; k < 3; ++k) mesh::turn_up(extruded, up);
      EXPECT_EQ(mesh::find_opening(extruded, "ring"), (mesh::Up{axis, 1}));
    }
  // Every generated die (the 1.2 mm slot's opening is its whole outline, its sides 6.7 times its area).
  for (const std::string& name : mesh::generated_die_names())
    EXPECT_EQ(mesh::find_opening(mesh::bundled_die(name), name), mesh::Up{}) << name;
  const geometry::TriMesh octahedron = octahedron_of(1e-2, 1e-2, 1e-2);
  try {
    mesh::find_opening(octahedron, "octahedron.stl");
    ADD_FAILURE() << "an octahedron has no opening";
  } catch (const diefill::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no flat face"), std::string::npos) << e.what();
  }
  EXPECT_EQ(mesh::parse_up("auto", "die.up"), std::nullopt);
  EXPECT_EQ(mesh::parse_up("-y", "die.up"), (mesh::Up{1, -1}));
  EXPECT_THROW(mesh::parse_up("up", "die.up"), diefill::InputError);
}

// A flat top that covers a small part of the outline is no opening: a flange plate (Ø20 mm, 2 mm)
// under a boss (Ø4 mm, 3 mm high: its top is 4 % of the shadow along z) is filled through the
// plate's face, below; the shadow along z is the plate's disc.
TEST(Orientation, ABossIsNoOpening) {
  geometry::TriMesh flange = mesh::ring_cavity(20e-3, 0, 2e-3, 1e-6);
  geometry::TriMesh boss = mesh::ring_cavity(4e-3, 0, 3e-3, 1e-6);
  for (Vec3& v : boss.vertices) v.z() += 3e-3;
  const geometry::TriMesh part = test::joined(flange, boss);
  EXPECT_NEAR(mesh::shadow_area(part, 2), std::numbers::pi * 1e-4, 0.01 * std::numbers::pi * 1e-4);
  EXPECT_EQ(mesh::find_opening(part, "flange"), (mesh::Up{2, -1}));
}

// An octahedron's sections are rhombi: cut at height t of its axis of half-length b, one with
// half-diagonals a and c has area 2ac(1 - |t|/b)², exactly, whatever its triangles.
TEST(Parting, SectionAreaOfAnOctahedronIsItsRhombus) {
  const double a = 10e-3, b = 6e-3, c = 20e-3;
  const geometry::TriMesh octahedron = octahedron_of(a, b, c);
  ASSERT_GT(geometry::signed_volume(octahedron), 0);
  for (const double t : {-19e-3, -7.5e-3, 0.0, 3e-3, 19.9e-3}) {
    const double rhombus = 2 * a * b * std::pow(1 - std::abs(t) / c, 2);
    EXPECT_NEAR(mesh::section_area(octahedron, t), rhombus, 1e-12 * a * b) << t;
  }
  EXPECT_EQ(mesh::section_area(octahedron, 21e-3), 0.0);
  // The widest of 256 levels: the two beside the equator are alike, and the higher is taken.
  EXPECT_NEAR(mesh::widest_section_z(octahedron), c / 256, 1e-15);
  // Its largest outline is along y (2ac, against 2bc and 2ab).
  EXPECT_EQ(mesh::lying_flat(octahedron), (mesh::Up{1, 1}));
  EXPECT_FALSE(mesh::has_flat_extreme(octahedron));
}

// A part with no flat face at any extreme (an octahedron, half-axes 10, 6 and 20 mm) is read
// lying flat, up along the axis of its largest outline (y), and cut at its widest section: the
// cavity is the part below, its volume 2ac b/3 (2 - (1 - h/b)³) for the cut h above the
// equator, its opening the rhombus there. die.parting = "opening" refuses it by name instead.
TEST(Parting, APartWithNoFlatFaceIsCutAtItsWidestSection) {
  const double a = 10e-3, b = 6e-3, c = 20e-3;
  const geometry::TriMesh octahedron = octahedron_of(a, b, c);
  test::TempDir dir;
  mesh::write_stl(octahedron, dir / "octahedron.stl", geometry::LengthUnit::mm, "octahedron");
  const mesh::DieFile file =
      mesh::read_die_file(dir / "octahedron.stl", geometry::LengthUnit::mm, std::nullopt, mesh::Parting::automatic);
  EXPECT_EQ(file.up, (mesh::Up{1, 1}));
  EXPECT_TRUE(file.up_found);
  ASSERT_TRUE(file.parting_z.has_value());
  const double h = b / 256;  // the higher of the two levels beside the equator
  EXPECT_NEAR(*file.parting_z, h, 1e-12);
  mesh::DieOptions options = mesh::die_options_for_grains(1e-3, 0.5e-3, 0.5e-3);
  const mesh::PreparedDie die = mesh::prepare_die(file, options, std::nullopt);
  const double below = 2 * a * c * b / 3 * (2 - std::pow(1 - h / b, 3));
  EXPECT_NEAR(geometry::signed_volume(die.cavity), below, 1e-9 * below);
  EXPECT_TRUE(die.after.closed);
  EXPECT_EQ(die.after.self_intersections, 0u);
  EXPECT_NEAR(geometry::bounding_box(die.cavity).hi.z(), h, 1e-12);
  EXPECT_DOUBLE_EQ(die.table_z, geometry::bounding_box(die.cavity).hi.z());
  EXPECT_NEAR(mesh::opening_area(die.cavity, mesh::Up{}), 2 * a * c * std::pow(1 - h / b, 2), 1e-9 * a * c);
  ASSERT_EQ(die.actions.size(), 1u);
  EXPECT_NE(die.actions.front().find("widest section"), std::string::npos) << die.actions.front();
  try {
    mesh::read_die_file(dir / "octahedron.stl", geometry::LengthUnit::mm, std::nullopt, mesh::Parting::opening);
    ADD_FAILURE() << "an octahedron has no flat opening";
  } catch (const diefill::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("octahedron.stl"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no flat face"), std::string::npos) << e.what();
  }
  EXPECT_EQ(mesh::parse_parting("widest", "die.parting"), mesh::Parting::widest);
  EXPECT_THROW(mesh::parse_parting("middle", "die.parting"), diefill::InputError);
}

// Read from a file with its opening facing -x, the die is the same cavity as the one facing up:
// the same triangles in the same places, up to the file's single precision.
TEST(Orientation, ADieFileOnItsSideIsReadFacingUp) {
  test::TempDir dir;
  const geometry::TriMesh ring = disc_with_one_flat_end();
  geometry::TriMesh lying = ring;
  for (int k = 0; k < 3; ++k) mesh::turn_up(lying, mesh::Up{0, -1});
  mesh::write_stl(lying, dir / "lying.stl", geometry::LengthUnit::mm, "ring on its side");
  mesh::write_stl(ring, dir / "upright.stl", geometry::LengthUnit::mm, "ring");
  const mesh::DieFile found = mesh::read_die_file(dir / "lying.stl", geometry::LengthUnit::mm, std::nullopt);
  const mesh::DieFile upright = mesh::read_die_file(dir / "upright.stl", geometry::LengthUnit::mm, std::nullopt);
  EXPECT_TRUE(found.up_found);
  EXPECT_EQ(found.up, (mesh::Up{0, -1}));
  EXPECT_EQ(upright.up, mesh::Up{});
  ASSERT_EQ(found.mesh.triangles.size(), upright.mesh.triangles.size());
  EXPECT_NEAR(geometry::signed_volume(found.mesh), geometry::signed_volume(upright.mesh), 1e-6 * geometry::signed_volume(upright.mesh));
  const geometry::Box a = geometry::bounding_box(found.mesh), b = geometry::bounding_box(upright.mesh);
  EXPECT_LT((a.lo - b.lo).norm() + (a.hi - b.hi).norm(), 1e-8);
}

// An assembly's file (docs/MESHES.md, "Assemblies"): a 4 mm cube, a 20 x 20 x 8 mm plate and a second
// cube, bodies that share no vertex. die.part keeps one, numbered by volume, largest first, the
// file's order breaking the cubes' tie; a part the file does not hold is refused naming the count
// and the largest; each part is its own cache entry.
TEST(Assembly, APartIsOneBodyOfTheFileNumberedByVolume) {
  const geometry::TriMesh cube = test::box_mm(0, 4);
  const geometry::TriMesh plate = mesh::box_solid(Vec3(10e-3, 0, 0), Vec3(30e-3, 20e-3, 8e-3));
  const geometry::TriMesh second_cube = mesh::box_solid(Vec3(40e-3, 0, 0), Vec3(44e-3, 4e-3, 4e-3));
  test::TempDir dir;
  const auto path = dir / "assembly.stl";
  test::write_text(path, test::ascii_stl(test::joined(test::joined(cube, plate), second_cube)));
  const auto part = [&](int k) {
    return mesh::read_die_file(path, geometry::LengthUnit::mm, mesh::Up{}, mesh::Parting::automatic, k);
  };
  const mesh::DieFile whole = part(0), largest = part(1), second = part(2), third = part(3);
  EXPECT_NEAR(geometry::signed_volume(whole.mesh), 3200e-9 + 2 * 64e-9, 1e-15);
  EXPECT_EQ(whole.mesh.triangles.size(), 36u);
  EXPECT_NEAR(geometry::signed_volume(largest.mesh), 3200e-9, 1e-15);
  EXPECT_NEAR(geometry::bounding_box(largest.mesh).lo.x(), 10e-3, 1e-9);
  EXPECT_NEAR(geometry::signed_volume(second.mesh), 64e-9, 1e-16);
  EXPECT_NEAR(geometry::bounding_box(second.mesh).lo.x(), 0, 1e-9);
  EXPECT_NEAR(geometry::bounding_box(third.mesh).lo.x(), 40e-3, 1e-9);
  EXPECT_EQ(third.part, 3);
  EXPECT_EQ(whole.bodies, 3u);
  try {
    part(4);
    ADD_FAILURE() << "the file holds three bodies";
  } catch (const diefill::InputError& e) {
    const std::string what = e.what();
    for (const char* named : {"assembly.stl", "part 4", "3 separate bodies", "1: 3200 mm³", "from 1 to 3"})
      EXPECT_NE(what.find(named), std::string::npos) << named << " in: " << what;
  }
  const mesh::DieOptions options = mesh::die_options_for_grains(1e-3, 0.5e-3, 0.5e-3);
  EXPECT_NE(mesh::die_cache_key(largest, std::nullopt, options), mesh::die_cache_key(second, std::nullopt, options));
  EXPECT_NE(mesh::die_cache_key(whole, std::nullopt, options), mesh::die_cache_key(largest, std::nullopt, options));
}

TEST(Import, ReadsFormatsAndWeldsToTheSameSolid) {
  test::TempDir dir;
  const geometry::TriMesh box = test::box_mm(0, 10);
  mesh::write_stl(box, dir / "box_bin.stl", geometry::LengthUnit::mm, "solid but binary");
  test::write_text(dir / "box_ascii.stl", test::ascii_stl(box));
  std::string obj, off = "OFF\n8 12 0\n", ply;
  for (const Vec3& v : box.vertices) {
    obj += fmt::format("v {} {} {}\n", v.x() * 1e3, v.y() * 1e3, v.z() * 1e3);
    off += fmt::format("{} {} {}\n", v.x() * 1e3, v.y() * 1e3, v.z() * 1e3);
  }
  ply = "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 12\nproperty list uchar int vertex_indices\nend_header\n";
  for (const Vec3& v : box.vertices) ply += fmt::format("{} {} {}\n", v.x() * 1e3, v.y() * 1e3, v.z() * 1e3);
  for (const auto& t : box.triangles) {
    obj += fmt::format("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    off += fmt::format("3 {} {} {}\n", t[0], t[1], t[2]);
    ply += fmt::format("3 {} {} {}\n", t[0], t[1], t[2]);
  }
  test::write_text(dir / "box.obj", obj);
  test::write_text(dir / "box.off", off);
  test::write_text(dir / "box.ply", ply);
  for (const char* file : {"box_bin.stl", "box_ascii.stl", "box.obj", "box.off", "box.ply"}) {
    const mesh::ImportResult r = mesh::import_mesh(dir / file);
    EXPECT_EQ(r.mesh.triangles.size(), 12u) << file;
    EXPECT_EQ(r.mesh.vertices.size(), 8u) << file << ": duplicate vertices welded";
    EXPECT_NEAR(geometry::signed_volume(r.mesh), 1e-6, 1e-15) << file;
  }
  EXPECT_EQ(mesh::import_mesh(dir / "box_bin.stl").vertices_welded, 36u - 8u);
}

TEST(Import, JoinsSeveralSolidsOfOneFile) {
  test::TempDir dir;
  const geometry::TriMesh a = test::box_mm(0, 1), b = test::box_mm(2, 3);
  test::write_text(dir / "two.stl", test::ascii_stl(a, 1e3, "a") + test::ascii_stl(b, 1e3, "b"));
  std::string obj;
  for (const auto* part : {&a, &b}) {
    obj += part == &a ? "o a\n" : "o b\n";
    for (const Vec3& v : part->vertices) obj += fmt::format("v {} {} {}\n", v.x() * 1e3, v.y() * 1e3, v.z() * 1e3);
    const int base = part == &a ? 1 : 9;
    for (const auto& t : part->triangles) obj += fmt::format("f {} {} {}\n", t[0] + base, t[1] + base, t[2] + base);
  }
  test::write_text(dir / "two.obj", obj);
  for (const char* file : {"two.stl", "two.obj"}) {
    const mesh::ImportResult r = mesh::import_mesh(dir / file);
    EXPECT_EQ(r.mesh.triangles.size(), 24u) << file;
    EXPECT_EQ(r.mesh.vertices.size(), 16u) << file;
    EXPECT_NEAR(geometry::signed_volume(r.mesh), 2e-9, 1e-18) << file;
  }
  EXPECT_EQ(mesh::import_mesh(dir / "two.obj").meshes_joined, 2) << "one mesh per OBJ object";
}

TEST(Import, AppliesDeclaredUnitAndWarnsWhenImplausible) {
  test::TempDir dir;
  mesh::write_stl(test::box_mm(0, 10), dir / "box.stl", geometry::LengthUnit::mm, "box");
  const mesh::ImportResult inches = mesh::import_mesh(dir / "box.stl", {geometry::LengthUnit::in});
  EXPECT_NEAR(geometry::bounding_box(inches.mesh).size().x(), 10 * 0.0254, 1e-12);
  EXPECT_TRUE(inches.warnings.empty());
  const mesh::ImportResult metres = mesh::import_mesh(dir / "box.stl", {geometry::LengthUnit::m});
  ASSERT_EQ(metres.warnings.size(), 1u) << "10 m is no die";
  EXPECT_NE(metres.warnings[0].find("units"), std::string::npos);
}

// No unit given: the file's numbers say it (docs/MESHES.md, "Units"). A box 10 across is millimetres and
// read silently; 2 across, inches; 0.1 across, metres; each guess other than mm is a warning.
TEST(Import, GuessesAnUndeclaredUnitFromTheSize) {
  test::TempDir dir;
  const struct {
    double side;
    geometry::LengthUnit unit;
  } cases[] = {{10, geometry::LengthUnit::mm}, {3, geometry::LengthUnit::mm}, {2.9, geometry::LengthUnit::in},
               {1, geometry::LengthUnit::in}, {0.99, geometry::LengthUnit::m}, {0.1, geometry::LengthUnit::m}};
  for (const auto& c : cases) {
    // Written in metres, so that the file's numbers are the side as given.
    mesh::write_stl(test::box_mm(0, 1e3 * c.side), dir / "box.stl", geometry::LengthUnit::m, "box");
    const mesh::ImportResult r = mesh::import_mesh(dir / "box.stl", {std::nullopt});
    EXPECT_EQ(r.unit, c.unit) << c.side;
    EXPECT_TRUE(r.unit_guessed);
    // STL stores single-precision coordinates: equal to a part in 10⁷.
    const double side = c.side * geometry::metres_per_unit(c.unit);
    EXPECT_NEAR(geometry::bounding_box(r.mesh).size().x(), side, 1e-7 * side) << c.side;
    EXPECT_EQ(r.warnings.size(), c.unit == geometry::LengthUnit::mm ? 0u : 1u) << c.side;
    const mesh::ImportResult declared = mesh::import_mesh(dir / "box.stl", {geometry::LengthUnit::mm});
    EXPECT_FALSE(declared.unit_guessed);
    EXPECT_EQ(declared.unit, geometry::LengthUnit::mm) << "a declared unit is never second-guessed";
  }
}

TEST(Import, RejectsFilesThatHoldNoMesh) {
  test::TempDir dir;
  auto expect_error = [&](const std::filesystem::path& path, const std::string& words) {
    try {
      mesh::import_mesh(path);
      ADD_FAILURE() << path << " was accepted";
    } catch (const diefill::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  expect_error(dir / "missing.stl", "no such file");
  expect_error(dir.path(), "is a directory");
  test::write_text(dir / "empty.stl", "");
  expect_error(dir / "empty.stl", "empty");
  test::write_text(dir / "garbage.stl", "this is not a mesh at all\n\x01\x02 just words\n");
  expect_error(dir / "garbage.stl", "not a readable mesh");
  std::string nan_solid = test::ascii_stl(test::box_mm(0, 1));
  nan_solid.replace(nan_solid.find("vertex ") + 7, 1, "nan");
  test::write_text(dir / "nan.stl", nan_solid);
  expect_error(dir / "nan.stl", "not a finite number");
}
