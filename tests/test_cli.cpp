// The command line: version, and bad input of every kind ends with a clear message and exit
// status 2 (run under AddressSanitizer and UBSan by scripts/test.sh).
#include <gtest/gtest.h>

#include <fmt/core.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <nlohmann/json.hpp>

#include "mesh/import.hpp"
#include "mesh/shapes.hpp"
#include "meshes.hpp"
#include "support.hpp"

namespace fs = std::filesystem;

namespace {

// Expects exit status 2 and a message that names `file` and contains `words`.
void expect_bad_input(const std::string& arguments, const std::string& file, const std::string& words) {
  const test::Run run = test::run_diefill(arguments);
  EXPECT_EQ(run.status, 2) << arguments << "\n" << run.output;
  EXPECT_NE(run.output.find(file), std::string::npos) << run.output;
  EXPECT_NE(run.output.find(words), std::string::npos) << run.output;
  EXPECT_EQ(run.output.find("Sanitizer"), std::string::npos) << run.output;
}

}  // namespace

TEST(Cli, VersionListsTheLibraries) {
  const test::Run run = test::run_diefill("--version");
  EXPECT_EQ(run.status, 0);
  for (const char* library : {"diefill", "CGAL 5.", "OpenVDB 10.", "assimp 5.", "Embree 3.", "Eigen 3."})
    EXPECT_NE(run.output.find(library), std::string::npos) << library << "\n" << run.output;
}

TEST(Cli, UnknownOptionIsBadInput) {
  EXPECT_EQ(test::run_diefill("sdf --no-such-option x.stl").status, 2);
}

TEST(Cli, SdfRejectsBadMeshesClearly) {
  test::TempDir dir;
  const std::string d = dir.path().string();
  const geometry::TriMesh ring = mesh::bundled_die("ring");
  mesh::write_stl(ring, dir / "ring.stl", geometry::LengthUnit::mm, "ring");
  const std::string whole = test::read_text(dir / "ring.stl");

  expect_bad_input("sdf " + d + "/missing.stl", "missing.stl", "no such file");
  expect_bad_input("sdf " + d, d, "is a directory");
  test::write_text(dir / "empty.stl", "");
  expect_bad_input("sdf " + d + "/empty.stl", "empty.stl", "empty");
  test::write_text(dir / "truncated.stl", whole.substr(0, whole.size() / 2));
  expect_bad_input("sdf " + d + "/truncated.stl", "truncated.stl", "not a readable mesh");
  test::write_text(dir / "garbage.stl", "solid? no. \x7f\x01 random words, not facets\n");
  expect_bad_input("sdf " + d + "/garbage.stl", "garbage.stl", "not a readable mesh");
  std::string nan_solid = test::ascii_stl(test::box_mm(0, 10));
  nan_solid.replace(nan_solid.find("vertex ") + 7, 1, "nan");
  test::write_text(dir / "nan.stl", nan_solid);
  expect_bad_input("sdf " + d + "/nan.stl", "nan.stl", "not a finite number");
  test::write_text(dir / "triangle.stl",
                   "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                   "endloop\nendfacet\nendsolid t\n");
  expect_bad_input("sdf " + d + "/triangle.stl", "triangle.stl", "cannot enclose a solid");
  geometry::TriMesh open_box = test::box_mm(0, 10);
  open_box.triangles.resize(10);
  test::write_text(dir / "open_box.stl", test::ascii_stl(open_box));
  expect_bad_input("sdf --role tool " + d + "/open_box.stl", "open_box.stl", "boundary edges");
  test::write_text(dir / "flipped.stl", test::ascii_stl(test::reversed(test::box_mm(0, 10))));
  expect_bad_input("sdf --role tool " + d + "/flipped.stl", "flipped.stl", "inside out");
  test::write_text(dir / "nested.stl", test::ascii_stl(test::joined(test::box_mm(0, 10), test::box_mm(2, 8))));
  expect_bad_input("sdf --role tool " + d + "/nested.stl", "nested.stl", "inside another shell");
  mesh::write_stl(ring, dir / "ring_in_metres.stl", geometry::LengthUnit::m, "ring, m");
  // Declared millimetres, a ring stored in metres is too small for the voxel (undeclared, its
  // size says metres: docs/MESHES.md, "Units").
  expect_bad_input("sdf --units mm " + d + "/ring_in_metres.stl", "ring_in_metres.stl", "--units m");
  const test::Run guessed = test::run_diefill("sdf --voxel 0.5 " + d + "/ring_in_metres.stl");
  EXPECT_EQ(guessed.status, 0) << guessed.output;
  EXPECT_NE(guessed.output.find("read as m (20 mm across"), std::string::npos) << guessed.output;
  expect_bad_input("sdf --units furlong " + d + "/ring.stl", "--units", "unknown length unit");
  expect_bad_input("run --units furlong " + d + "/ring.stl", "--units", "unknown length unit");
  expect_bad_input("sdf --up sideways " + d + "/ring.stl", "--up", "not a direction");
  expect_bad_input("run --up sideways " + d + "/ring.stl", "--up", "not a direction");
  expect_bad_input("sdf --voxel -1 " + d + "/ring.stl", "voxel", "positive");
}

// A length flag takes its unit: the same voxel written as 1 or 1000um gives the same grid
// (its voxel, band and active voxels as `sdf` reports them); a unit it does not know is bad input
// naming the flag.
TEST(Cli, LengthFlagsTakeAUnit) {
  test::TempDir dir;
  mesh::write_stl(mesh::bundled_die("disc"), dir / "disc.stl", geometry::LengthUnit::mm, "disc");
  const auto grid_line = [&](const std::string& voxel) {
    const test::Run run = test::run_diefill("sdf " + (dir / "disc.stl").string() + " --voxel " + voxel + " -o " + (dir / "d.vdb").string());
    EXPECT_EQ(run.status, 0) << run.output;
    const std::size_t at = run.output.find("sdf: role");
    return at == std::string::npos ? std::string() : run.output.substr(at, run.output.find('\n', at) - at);
  };
  // Coarse voxels: under the sanitizers each grid takes seconds.
  const std::string bare = grid_line("1");
  ASSERT_NE(bare.find("voxel 1 mm"), std::string::npos) << bare;
  EXPECT_EQ(grid_line("1000um"), bare);
  expect_bad_input("sdf " + (dir / "disc.stl").string() + " --voxel 0.5furlong -o " + (dir / "x.vdb").string(), "--voxel",
                   "not a length");
}

TEST(Cli, FailedSdfKeepsTheEarlierOutput) {
  test::TempDir dir;
  mesh::write_stl(mesh::bundled_die("disc"), dir / "disc.stl", geometry::LengthUnit::mm, "disc");
  const std::string out = (dir / "disc.vdb").string();
  // Coarse voxels: this test is about files, and under the sanitizers a fine grid takes minutes.
  ASSERT_EQ(test::run_diefill("sdf " + (dir / "disc.stl").string() + " --voxel 0.5 -o " + out).status, 0);
  const std::string before = test::read_text(out);
  test::write_text(dir / "disc.stl", "garbage");
  EXPECT_EQ(test::run_diefill("sdf " + (dir / "disc.stl").string() + " -o " + out).status, 2);
  EXPECT_EQ(test::read_text(out), before);
}

namespace {
// A small scene: 200 grains above a floor, written into `dir`.
void write_scene(const test::TempDir& dir, const std::string& extra_simulation = "", double duration = 0.01) {
  std::string csv = "id,x,y,z,vx,vy,vz,wx,wy,wz,radius\n";
  for (int n = 0; n < 200; ++n)
    csv += fmt::format("{},{},{},{},0,0,-0.1,0,0,0,5e-4\n", n, (n % 10) * 1.1e-3, (n / 10 % 5) * 1.1e-3,
                       (n / 50) * 1.1e-3 + 1e-3);
  test::write_text(dir / "particles.csv", csv);
  test::write_text(dir / "scene.toml", fmt::format("[simulation]\nduration = {}\n", duration) + extra_simulation +
                                           "\n[[materials]]\nname = \"glass\"\nyoungs_modulus = 5e6\n"
                                           "\n[particles]\nfile = \"particles.csv\"\n"
                                           "\n[[walls]]\ntype = \"plane\"\nnormal = [0.0, 0.0, 1.0]\n"
                                           "\n[output]\ntrajectory = true\ntrajectory_every = 0.005\nsnapshot_every = 0.005\n");
}
}  // namespace

// A mesh wall of a simulate scene is built by the run, not by loading the scene: a grain dropped
// inside the disc die read as a closed container comes to rest on its floor, sunk into it by no
// more than the Hertz overlap of its weight (a fraction of a per cent of its radius); without the wall it
// would fall out of the domain.
TEST(CliSimulate, AMeshWallHoldsTheGrainsOnItsFloor) {
  test::TempDir dir;
  const geometry::TriMesh disc = mesh::bundled_die("disc");
  mesh::write_stl(disc, dir / "disc.stl", geometry::LengthUnit::mm, "disc");
  geometry::Vec3 lo = disc.vertices.front(), hi = lo;
  for (const geometry::Vec3& v : disc.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  const geometry::Vec3 centre = 0.5 * (lo + hi);
  const double r = 2e-3;  // a coarse wall field (its voxel a quarter of the radius): seconds under the sanitizers
  test::write_text(dir / "particles.csv", fmt::format("id,x,y,z,vx,vy,vz,wx,wy,wz,radius\n0,{},{},{},0,0,0,0,0,0,{}\n", centre.x(),
                                                      centre.y(), lo.z() + 4 * r, r));
  test::write_text(dir / "scene.toml", "[simulation]\nduration = 0.15\n\n[[materials]]\nname = \"glass\"\nyoungs_modulus = 5e6\n"
                                       "restitution = 0.2\n\n[particles]\nfile = \"particles.csv\"\n\n[[walls]]\ntype = \"mesh\"\n"
                                       "file = \"disc.stl\"\nrole = \"container\"\n");
  const test::Run run = test::run_diefill("simulate " + (dir / "scene.toml").string() + " -o " + (dir / "out").string());
  ASSERT_EQ(run.status, 0) << run.output;
  const std::string csv = test::read_text(dir / "out" / "particles.csv");
  const std::string row = csv.substr(csv.find('\n') + 1);
  std::vector<double> values;
  for (std::size_t at = 0; at < row.size() && values.size() < 4;) {
    const std::size_t end = row.find_first_of(",\n", at);
    values.push_back(std::stod(row.substr(at, end - at)));
    at = end + 1;
  }
  ASSERT_EQ(values.size(), 4u) << csv;
  EXPECT_NEAR(values[1], centre.x(), 1e-6);
  EXPECT_NEAR(values[2], centre.y(), 1e-6);
  EXPECT_LE(values[3], lo.z() + r) << "at rest on the floor, pressed into it";
  EXPECT_GE(values[3], lo.z() + 0.9 * r) << "not through the floor";
}

// Values that mean nothing and scenes too large to be meant are refused before any work, by
// `scene` as by `run` (issue 44): within seconds, naming the key, the model's compilation
// included; a size over the limit says how to go on, and --force accepts it.
TEST(CliScene, RefusesWhatRunWouldBeforeAnyWork) {
  const std::string ring = (test::source_dir() / "dies" / "ring.stl").string();
  test::TempDir dir;
  const auto started = std::chrono::steady_clock::now();
  expect_bad_input("run " + ring + " --set motion.speed=1e-300 --out " + (dir / "out").string(), "motion.speed", "[0.001, 10]");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count(), 10.0);
  EXPECT_FALSE(fs::exists(dir / "out" / "ring")) << "refused before the die was prepared";
  expect_bad_input("scene --set contact.normal=linear --set contact.linear_stiffness=0", "contact.linear_stiffness", "linear");
  expect_bad_input("scene --set motion.passes=2", "motion.passes", "motion.return");
  // The shoe at 10 m/s with a skin of 0.1 µm passes grains unseen: the pass's compilation refuses
  // it, which a run reached only after settling the shoe.
  expect_bad_input("scene " + ring + " --set motion.speed=10 --set simulation.skin=1e-7", "walls.shoe.motion", "skin");
  const std::string huge = " --set powder.coarse_graining=1 --set powder.max_grains=100000000 --set fem.elements=none";
  expect_bad_input("scene " + ring + huge, "ring.stl", "--force");
  const test::Run forced = test::run_diefill("scene " + ring + huge + " --force");
  EXPECT_EQ(forced.status, 0) << forced.output;
  // The shoe (32 mm, trimmed to the die's 20 mm and two 4 mm margins) filled 8 mm deep at 0.6 with
  // grains of 0.1 mm.
  const auto grains = std::size_t(32e-3 * 28e-3 * 8e-3 * 0.6 / (std::numbers::pi / 6 * 1e-12));
  EXPECT_NE(forced.output.find(fmt::format("{} grains", grains)), std::string::npos) << forced.output;
  const test::Run plain = test::run_diefill("scene " + ring);
  EXPECT_EQ(plain.status, 0) << plain.output;
  EXPECT_NE(plain.output.find("The run on ring: 16042 grains"), std::string::npos) << plain.output;
}

// A grain-size ladder the ring's 5 mm annulus cannot take (2.2 to 4.4 grains across) is refused
// before any run, naming the part and the α it needs; so are ladders that are no ladders.
TEST(CliLadder, RefusesWhatItCannotExtrapolateBeforeAnyRun) {
  const std::string ring = (test::source_dir() / "dies" / "ring.stl").string();
  test::TempDir dir;
  const std::string out = " --out " + (dir / "out").string();
  expect_bad_input("run " + ring + " --ladder 22.6,16,11.3 --extrapolate-to 8" + out, "--ladder", "5 mm wide");
  expect_bad_input("run " + ring + " --ladder 22.6,16,11.3" + out, "--ladder", "α of 10 or less");
  EXPECT_FALSE(fs::exists(dir / "out" / "powder.coarse_graining=22.6")) << "no level ran";
  expect_bad_input("run " + ring + " --ladder 16,8" + out, "--ladder", "three distinct levels");
  expect_bad_input("run " + ring + " --ladder 16,8,0.5" + out, "--ladder", "[1, 200]");
  expect_bad_input("run " + ring + " --extrapolate-to 8" + out, "--extrapolate-to", "--ladder");
  expect_bad_input("run " + ring + " --ladder 16,11.3,8 --seeds 1" + out, "--seeds", "two seeds");
  expect_bad_input("run " + ring + " --seeds 2 --resume" + out, "--seeds", "afresh");
}

TEST(CliSimulate, WritesTheFilesOfTheInterface) {
  test::TempDir dir;
  write_scene(dir);
  const test::Run run = test::run_diefill("simulate " + (dir / "scene.toml").string() + " --out " + (dir / "out").string());
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_EQ(test::read_text(dir / "out" / "particles.csv").rfind("id,x,y,z,vx,vy,vz,wx,wy,wz,radius,density\n", 0), 0u);
  EXPECT_EQ(test::read_text(dir / "out" / "trajectory.csv").rfind("t,id,x,y,z,vx,vy,vz,wx,wy,wz,fx,fy,fz\n", 0), 0u);
  const std::string vtu = test::read_text(dir / "out" / "snapshot_00000.vtu");
  for (const char* array : {"\"id\"", "\"radius\"", "\"velocity\"", "\"angular_velocity\"", "\"force\"", "\"body\""})
    EXPECT_NE(vtu.find(array), std::string::npos) << array;
  EXPECT_NE(test::read_text(dir / "out" / "summary.json").find("particle_steps_per_s"), std::string::npos);
}

// Ctrl-C halfway, then `--resume`: the outputs are the uninterrupted run's, byte for byte (the
// trajectory's rows before the interrupt kept, the snapshots numbered on, none written over).
TEST(CliSimulate, AResumedRunWritesTheUninterruptedRunsOutputs) {
  test::TempDir dir;
  write_scene(dir, "", 0.25);
  const std::string scene = (dir / "scene.toml").string();
  const auto started = std::chrono::steady_clock::now();
  ASSERT_EQ(test::run_diefill("simulate " + scene + " --out " + (dir / "whole").string()).status, 0);
  const double whole_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  // Stopped at 0.6 of the uninterrupted run's time, whatever this build's speed: about halfway
  // through its stepping, which follows a start of about 0.1 s in the Release build.
  const std::string interrupt = fmt::format("bash -c '{} simulate {} --out {} > /dev/null 2>&1 & pid=$!; sleep {:.3f}; "
                                            "kill -INT $pid; wait $pid; echo $? > {}'",
                                            DIEFILL_EXECUTABLE, scene, (dir / "part").string(), 0.6 * whole_s,
                                            (dir / "status").string());
  ASSERT_EQ(std::system(interrupt.c_str()), 0);
  ASSERT_EQ(test::read_text(dir / "status"), "130\n");
  ASSERT_TRUE(fs::exists(dir / "part" / "checkpoint.bin"));
  const test::Run resumed = test::run_diefill("simulate " + scene + " --out " + (dir / "part").string() + " --resume");
  ASSERT_EQ(resumed.status, 0) << resumed.output;
  std::size_t compared = 0;
  for (const auto& f : fs::directory_iterator(dir / "whole")) {
    const std::string name = f.path().filename().string();
    if (name == "summary.json") continue;  // timings
    EXPECT_TRUE(fs::exists(dir / "part" / name) && test::read_text(dir / "part" / name) == test::read_text(f.path())) << name;
    ++compared;
  }
  EXPECT_EQ(compared, 2u + 51u);  // particles.csv, trajectory.csv and the snapshots at 0, 0.005, ..., 0.25 s
}

TEST(CliSimulate, UnknownKeysAndBadValuesNameFileAndLine) {
  test::TempDir dir;
  write_scene(dir, "duratoin = 2.0");
  const test::Run typo = test::run_diefill("simulate " + (dir / "scene.toml").string());
  EXPECT_EQ(typo.status, 2) << typo.output;
  EXPECT_NE(typo.output.find("scene.toml:3: simulation.duratoin: unknown key"), std::string::npos) << typo.output;
  write_scene(dir, "gravity = \"down\"");
  const test::Run type = test::run_diefill("simulate " + (dir / "scene.toml").string());
  EXPECT_EQ(type.status, 2);
  EXPECT_NE(type.output.find("simulation.gravity: must be an array of three numbers"), std::string::npos) << type.output;
  write_scene(dir);
  test::write_text(dir / "particles.csv", "id,x,y,z,vx,vy,vz,wx,wy,wz\n0,0,0,0,0,0,0,0,0,0\n");
  const test::Run columns = test::run_diefill("simulate " + (dir / "scene.toml").string());
  EXPECT_EQ(columns.status, 2);
  EXPECT_NE(columns.output.find("column radius: is missing"), std::string::npos) << columns.output;
}

TEST(CliSimulate, UnstableStepStopsWithStatus3AndACheckpoint) {
  test::TempDir dir;
  write_scene(dir, "time_step = 2e-4");
  const test::Run run = test::run_diefill("simulate " + (dir / "scene.toml").string() + " --out " + (dir / "out").string());
  EXPECT_EQ(run.status, 3) << run.output;
  EXPECT_NE(run.output.find("time step"), std::string::npos) << run.output;
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "checkpoint.bin"));
}

namespace {
// Grains of 2 mm on a loose lattice in the disc cavity, as a particles CSV. The command seeds
// its die queries with voxels of half the grain radius; with 1 mm grains the unoptimised
// sanitizer build spent 46 s building that field (14 s with these).
void write_disc_particles(const std::filesystem::path& path) {
  std::string csv = "id,x,y,z,vx,vy,vz,wx,wy,wz,radius,density\n";
  int id = 0;
  for (int i = -4; i <= 4; ++i)
    for (int j = -4; j <= 4; ++j)
      for (int k = 0; k < 4; ++k) {
        const double x = i * 2.1e-3, y = j * 2.1e-3, z = -8.9e-3 + k * 2.1e-3;
        if (std::hypot(x, y) < 8.9e-3) csv += fmt::format("{},{},{},{},0,0,0,0,0,0,1e-3,7800\n", id++, x, y, z);
      }
  test::write_text(path, csv);
}
}  // namespace

TEST(CliDensity, WritesAFieldThatOpenVdbReadsBack) {
  test::TempDir dir;
  write_disc_particles(dir / "grains.csv");
  const std::string out = (dir / "field").string();
  const test::Run run = test::run_diefill("density " + (dir / "grains.csv").string() + " --die " +
                                          (test::source_dir() / "dies" / "disc.stl").string() + " --voxel 1 --coarse-graining 8 -o " + out);
  ASSERT_EQ(run.status, 0) << run.output;
  for (const char* file : {"density.vdb", "density.vti", "density.json", "top_view.png", "sections.png", "histogram.png"})
    EXPECT_TRUE(std::filesystem::exists(dir / "field" / file)) << file;
  // An independent reader: OpenVDB's Python module recomputes the cavity-weighted mean.
  test::write_text(dir / "check.py", R"(
import json, sys
import pyopenvdb as vdb
grids, meta = vdb.readAll(sys.argv[1] + "/density.vdb")
names = sorted(g.name for g in grids)
g = {x.name: x for x in grids}
phi, cav, rho = g["solid_fraction"], g["cavity_fraction"], g["density"]
acc_phi, acc_rho = phi.getConstAccessor(), rho.getConstAccessor()
num = den = worst = 0.0
for item in cav.citerOnValues():
    ijk = item.min
    w = item.value
    num += w * acc_phi.getValue(ijk)
    den += w
    worst = max(worst, abs(acc_rho.getValue(ijk) - 7800 * acc_phi.getValue(ijk)))
report = json.load(open(sys.argv[1] + "/density.json"))
print(json.dumps({"names": names, "voxel": phi.transform.voxelSize()[0], "units": phi["units"],
                  "coarse_graining": phi["coarse_graining"], "die": phi["die"], "sha": phi["die_sha256"], "grains": phi["grains"], "material_density": phi["material_density"],
                  "mean": num / den, "report_mean": report["fill"]["solid_fraction_mean"], "density_error": worst,
                  "origin": list(phi.transform.indexToWorld((0, 0, 0)))}))
)");
  const std::string python = "/usr/bin/python3 " + (dir / "check.py").string() + " " + out + " 2>&1";
  FILE* pipe = ::popen(python.c_str(), "r");
  std::string text;
  char buffer[4096];
  while (std::size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) text.append(buffer, n);
  ASSERT_EQ(::pclose(pipe), 0) << text;
  const auto j = nlohmann::json::parse(text);
  EXPECT_EQ(j["names"], nlohmann::json({"cavity_fraction", "density", "merged", "smoothed_cavity_fraction", "smoothed_density",
                                        "smoothed_solid_fraction", "solid_fraction"}));
  EXPECT_DOUBLE_EQ(j["voxel"].get<double>(), 1e-3);
  EXPECT_EQ(j["units"], "m");
  EXPECT_EQ(j["coarse_graining"], "8");  // as the pipeline's field records it
  EXPECT_EQ(j["die"], "disc");
  EXPECT_EQ(j["sha"].get<std::string>().size(), 64u);
  EXPECT_DOUBLE_EQ(j["material_density"].get<double>(), 7800);
  EXPECT_NEAR(j["mean"].get<double>(), j["report_mean"].get<double>(), 1e-6);
  EXPECT_LT(j["density_error"].get<double>(), 1e-2);
  // vdb_print, Debian's command-line reader, lists the grids.
  FILE* p2 = ::popen(("vdb_print " + out + "/density.vdb 2>&1").c_str(), "r");
  std::string printed;
  while (std::size_t n = std::fread(buffer, 1, sizeof buffer, p2)) printed.append(buffer, n);
  ::pclose(p2);
  for (const char* grid : {"solid_fraction", "density", "cavity_fraction"}) EXPECT_NE(printed.find(grid), std::string::npos) << printed;
}

TEST(CliDensity, BadInputLeavesNoPartialOutput) {
  test::TempDir dir;
  const std::string die = " --die " + (test::source_dir() / "dies" / "disc.stl").string();
  auto expect_refused = [&](const std::string& csv, const std::string& words, const std::string& die_args) {
    test::write_text(dir / "grains.csv", csv);
    const test::Run run = test::run_diefill("density " + (dir / "grains.csv").string() + die_args + " -o " + (dir / "out").string());
    EXPECT_EQ(run.status, 2) << run.output;
    EXPECT_NE(run.output.find(words), std::string::npos) << run.output;
    EXPECT_TRUE(!std::filesystem::exists(dir / "out") || std::filesystem::is_empty(dir / "out")) << "partial output";
  };
  expect_refused("id,x,y,z,vx,vy,vz,wx,wy,wz\n1,0,0,-0.005,0,0,0,0,0,0\n", "column radius", die);
  expect_refused("id,x,y,z,vx,vy,vz,wx,wy,wz,radius\n1,nan,0,-0.005,0,0,0,0,0,0,5e-4\n", "not a finite number", die);
  expect_refused("id,x,y,z,vx,vy,vz,wx,wy,wz,radius,density\n1,0.5,0.5,0.5,0,0,0,0,0,0,1e-3,7800\n", "lies in the cavity", die);
}

// compare and sweep refuse what they cannot do (not a run's folder, a broken or older report, a
// sweep without values or over a folder), naming the folder or the option, and write nothing.
TEST(CliCompare, RefusesFoldersThatAreNotRunsAndBadSweeps) {
  test::TempDir dir;
  std::filesystem::create_directories(dir / "empty");
  std::filesystem::create_directories(dir / "broken");
  const std::string out = " -o " + (dir / "compared").string();
  expect_bad_input("compare " + (dir / "empty").string() + " " + (dir / "empty").string() + out, "report.json", "not a run's folder");
  test::write_text(dir / "broken" / "report.json", "{not json");
  expect_bad_input("compare " + (dir / "broken").string() + " " + (dir / "broken").string() + out, "report.json", "is not JSON");
  std::filesystem::create_directories(dir / "old");
  test::write_text(dir / "old" / "report.json", R"({"die": {"sha256": "0", "name": "ring"}, "fill": {"fill_ratio": 0.5}})");
  expect_bad_input("compare " + (dir / "old").string() + " " + (dir / "old").string() + out, "/run/seed", "older diefill");
  EXPECT_FALSE(std::filesystem::exists(dir / "compared"));
  expect_bad_input("run " + (test::source_dir() / "dies" / "ring.stl").string() + " --sweep motion.speed --out " + (dir / "swept").string(),
                   "--sweep", "KEY=VALUE");
  expect_bad_input("run " + (test::source_dir() / "dies").string() + " --sweep motion.speed=0.1,0.2 --out " + (dir / "swept").string(),
                   "--sweep", "not a folder");
  EXPECT_FALSE(std::filesystem::exists(dir / "swept"));
}

// `diefill sdf -o FILE.vdb` writes the distance grid alone: OpenVDB's own Python module refused
// the whole file while it also held the Int32 grid of closest triangles (kept in the cache).
TEST(CliSdf, OutputOpensInOpenVdbsPythonModule) {
  test::TempDir dir;
  const std::string out = (dir / "ring.vdb").string();
  const test::Run run = test::run_diefill("sdf " + (test::source_dir() / "dies" / "ring.stl").string() + " --voxel 0.5 -o " + out);
  ASSERT_EQ(run.status, 0) << run.output;
  const test::Run py = test::run_command(
      "/usr/bin/python3 -c 'import sys, pyopenvdb as v; g, m = v.readAll(sys.argv[1]); print(\" \".join(x.name for x in g), "
      "g[0][\"units\"])' " + out + " 2>&1");
  EXPECT_EQ(py.status, 0) << py.output;
  EXPECT_EQ(py.output, "sdf m\n");
}

// `diefill clump MESH -o grain.json` writes that file (the interface promises it), with the
// errors beside it; it wrote a folder named grain.json.
TEST(CliClump, OutputEndingInJsonIsTheTemplateFile) {
  test::TempDir dir;
  // An octahedron-like grain: a box is the simplest closed grain mesh at hand; a loose tolerance.
  test::write_text(dir / "grain.stl", test::ascii_stl(test::box_mm(0, 2)));
  const test::Run run = test::run_diefill("clump " + (dir / "grain.stl").string() + " --tolerance 0.25 -o " +
                                          (dir / "out" / "grain.json").string());
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_TRUE(std::filesystem::is_regular_file(dir / "out" / "grain.json"));
  EXPECT_TRUE(std::filesystem::is_regular_file(dir / "out" / "grain_errors.csv"));
  const auto clump = nlohmann::json::parse(test::read_text(dir / "out" / "grain.json"));
  EXPECT_GE(clump["spheres"].size(), 1u);
}
