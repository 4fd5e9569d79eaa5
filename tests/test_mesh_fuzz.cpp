// Meshes as users' tools write them, and worse: a small die mutated at random (bytes flipped,
// coordinates made NaN or huge, triangles dropped, doubled or reversed, files cut short) goes
// through the whole mesh stage and either prepares or is refused with InputError; nothing else
// may escape, and nothing may crash or hang (run under the sanitizers too).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "core/error.hpp"
#include "mesh/die.hpp"
#include "mesh/import.hpp"
#include "mesh/shapes.hpp"
#include "meshes.hpp"
#include "support.hpp"

using geometry::Vec3;

namespace {

// A 10 mm cube cavity with a 4 mm cube standing in it: small, but with the features repair meets.
geometry::TriMesh small_die() {
  return test::joined(mesh::box_solid(Vec3(0, 0, -10e-3), Vec3(10e-3, 10e-3, 0)),
                      test::reversed(mesh::box_solid(Vec3(3e-3, 3e-3, -10e-3), Vec3(7e-3, 7e-3, -6e-3))));
}

geometry::TriMesh mutated_mesh(geometry::TriMesh m, std::mt19937_64& random) {
  const double values[] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(), 1e30, -1e-30, 0, 5e-3};
  for (int k = 0; k < 1 + int(random() % 4); ++k) {
    switch (random() % 5) {
      case 0: m.vertices[random() % m.vertices.size()][int(random() % 3)] = values[random() % 6]; break;
      case 1: if (m.triangles.size() > 1) m.triangles.erase(m.triangles.begin() + std::ptrdiff_t(random() % m.triangles.size())); break;
      case 2: m.triangles.push_back(m.triangles[random() % m.triangles.size()]); break;
      case 3: std::swap(m.triangles[random() % m.triangles.size()][0], m.triangles[random() % m.triangles.size()][1]); break;
      case 4: m.vertices[random() % m.vertices.size()] += Vec3(1e-3, -2e-3, 0.5e-3); break;
    }
  }
  return m;
}

// The dies come in blocks of 25, each its own CTest test, so that `ctest -j` spreads them over the
// cores (as one test, the 100 dies the sanitizers take were the critical path of CI's sanitizer
// stage: 487 s of its ~700 s of tests). Under AddressSanitizer the mesh stage runs six times
// slower: the sanitizers take the first 2 blocks (50 dies, every outcome among them: 4 blocks
// were 97-169 s each, three quarters of the stage's test time, with CI at 2312 s against its 30
// minutes); the Release run takes all 12. Each die draws its mutations from its own seed, so a
// block is the same dies whichever blocks run.
constexpr int dies_per_block = 25;
#ifdef __SANITIZE_ADDRESS__
constexpr int blocks = 2;
#else
constexpr int blocks = 12;
#endif

std::string mutated_bytes(std::string bytes, std::mt19937_64& random) {
  if (random() % 3 == 0) return bytes.substr(0, random() % bytes.size());  // cut short
  for (int k = 0; k < 1 + int(random() % 16); ++k) bytes[random() % bytes.size()] = char(random());
  return bytes;
}

}  // namespace

class MeshFuzz : public ::testing::TestWithParam<int> {};

TEST_P(MeshFuzz, MutatedDiesPrepareOrAreRefusedClearly) {
  test::TempDir dir;
  const geometry::TriMesh die = small_die();
  mesh::write_stl(die, dir / "clean.stl", geometry::LengthUnit::mm, "fuzz");
  const std::string clean = test::read_text(dir / "clean.stl");
  mesh::DieOptions options = mesh::die_options_for_grains(1e-3, 0.5e-3, 0.5e-3);
  int prepared = 0, refused = 0;
  for (int n = GetParam() * dies_per_block; n < (GetParam() + 1) * dies_per_block; ++n) {
    std::mt19937_64 random(16 + std::uint64_t(n));
    const std::filesystem::path file = dir / "die.stl";
    if (n % 2 == 0) mesh::write_stl(mutated_mesh(die, random), file, geometry::LengthUnit::mm, "fuzz");
    else test::write_text(file, mutated_bytes(clean, random));
    options.role = n % 3 == 0 ? mesh::WallRole::tool : mesh::WallRole::cavity;
    try {
      const mesh::PreparedDie p = mesh::prepare_die(file, options, std::nullopt);
      EXPECT_GT(p.sdf.active_voxels(), 0u);
      ++prepared;
    } catch (const diefill::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
      ++refused;
    }
  }
  std::printf("mutated dies: %d prepared, %d refused\n", prepared, refused);
  // Both ways out were taken: the mutations reach the repair and the refusals alike.
  EXPECT_GT(refused, 0);
  EXPECT_GT(prepared, 0);
}

INSTANTIATE_TEST_SUITE_P(Blocks, MeshFuzz, ::testing::Range(0, blocks));
