// mesh/import and mesh/shapes: formats, joining, welding, units, and the bundled dies.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/error.hpp"
#include "mesh/import.hpp"
#include "mesh/shapes.hpp"
#include "meshes.hpp"
#include "support.hpp"

using mesh::Vec3;

namespace {

double polygon_annulus_volume(double ro, double ri, double depth, int n) {
  // A regular n-gon inscribed in a circle of radius r has area n/2 r² sin(2π/n).
  return 0.5 * n * std::sin(2 * std::numbers::pi / n) * (ro * ro - ri * ri) * depth;
}

}  // namespace

TEST(BundledDies, MeetChordToleranceAndAnalyticVolume) {
  for (const auto& [name, inner] : {std::pair{"ring", 10e-3}, std::pair{"disc", 0.0}}) {
    const mesh::TriMesh die = mesh::bundled_die(name);
    const int n = mesh::circle_segments(10e-3, 5e-6);
    EXPECT_LT(mesh::chord_error(10e-3, n), 0.01e-3) << name;
    EXPECT_NEAR(mesh::signed_volume(die), polygon_annulus_volume(10e-3, inner / 2, 10e-3, n), 1e-15)
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
    const mesh::Box box = mesh::bounding_box(die);
    EXPECT_DOUBLE_EQ(box.hi.z(), 0.0) << name << ": top face on the die table";
    EXPECT_DOUBLE_EQ(box.lo.z(), -10e-3) << name;
  }
}

TEST(BundledDies, FilesInDiesAreTheGeneratedOnes) {
  test::TempDir dir;
  for (const std::string& name : mesh::bundled_die_names()) {
    const auto regenerated = dir / (name + ".stl");
    mesh::write_stl(mesh::bundled_die(name), regenerated, mesh::LengthUnit::mm,
                    "diefill " + name + " cavity, mm");
    EXPECT_EQ(test::read_text(regenerated), test::read_text(test::source_dir() / "dies" / (name + ".stl")))
        << "dies/" << name << ".stl differs from `diefill die " << name << "`";
  }
}

TEST(Import, ReadsFormatsAndWeldsToTheSameSolid) {
  test::TempDir dir;
  const mesh::TriMesh box = test::box_mm(0, 10);
  mesh::write_stl(box, dir / "box_bin.stl", mesh::LengthUnit::mm, "solid but binary");
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
    EXPECT_NEAR(mesh::signed_volume(r.mesh), 1e-6, 1e-15) << file;
  }
  EXPECT_EQ(mesh::import_mesh(dir / "box_bin.stl").vertices_welded, 36u - 8u);
}

TEST(Import, JoinsSeveralSolidsOfOneFile) {
  test::TempDir dir;
  const mesh::TriMesh a = test::box_mm(0, 1), b = test::box_mm(2, 3);
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
    EXPECT_NEAR(mesh::signed_volume(r.mesh), 2e-9, 1e-18) << file;
  }
  EXPECT_EQ(mesh::import_mesh(dir / "two.obj").meshes_joined, 2) << "one mesh per OBJ object";
}

TEST(Import, AppliesDeclaredUnitAndWarnsWhenImplausible) {
  test::TempDir dir;
  mesh::write_stl(test::box_mm(0, 10), dir / "box.stl", mesh::LengthUnit::mm, "box");
  const mesh::ImportResult inches = mesh::import_mesh(dir / "box.stl", {mesh::LengthUnit::in});
  EXPECT_NEAR(mesh::bounding_box(inches.mesh).size().x(), 10 * 0.0254, 1e-12);
  EXPECT_TRUE(inches.warnings.empty());
  const mesh::ImportResult metres = mesh::import_mesh(dir / "box.stl", {mesh::LengthUnit::m});
  ASSERT_EQ(metres.warnings.size(), 1u) << "10 m is no die";
  EXPECT_NE(metres.warnings[0].find("units"), std::string::npos);
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
