// Conservation and reproducibility: energy and momentum in a gas of elastic grains,
// bit-identical states for any thread count and across a checkpoint.
#include <gtest/gtest.h>
#include <omp.h>

#include "core/error.hpp"
#include "dem/checkpoint.hpp"
#include "dem/insert.hpp"
#include "dem_support.hpp"
#include "dem/forces.hpp"
#include "mesh/exact.hpp"
#include "mesh/shapes.hpp"
#include "mesh/tool.hpp"
#include "support.hpp"

using dem::Vec3;

namespace {

// Elastic, frictionless grains with random velocities in a box of planes.
dem::ModelSpec gas_spec(bool walls) {
  dem::ModelSpec spec = test::spec_with({test::glass(1.0, 0.0), test::rigid_wall(1.0, 0.0)});
  spec.law.tangential = "none";
  spec.max_impact_speed = 1.0;
  spec.time_step_fraction = 0.02;
  spec.domain.lo = Vec3::Constant(-6e-3);
  spec.domain.hi = Vec3::Constant(6e-3);
  if (walls)
    for (int a = 0; a < 3; ++a)
      for (int side : {-1, 1}) {
        Vec3 n = Vec3::Zero();
        n[a] = -side;
        spec.planes.push_back({Vec3::Unit(a) * side * 5e-3, n, 1, "box"});
      }
  return spec;
}

dem::State gas(std::size_t count, std::uint64_t seed, double speed) {
  dem::State s;
  dem::InsertRegion region;
  region.box = {Vec3::Constant(-4.9e-3), Vec3::Constant(4.9e-3)};
  dem::InsertRequest req;
  req.count = count;
  req.radius = 0.3e-3;
  req.radius_spread = 0.2;
  req.seed = seed;
  dem::insert_spheres(s, region, req);
  dem::Random random(seed + 1);
  for (Vec3& v : s.v) v = speed * Vec3(random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1));
  return s;
}

// Counts pair contacts that begin during the run.
std::int64_t run_counting_collisions(const dem::Model& model, dem::State& s, std::int64_t collisions) {
  std::int64_t begun = 0, previous = s.counters.contacts;
  while (begun < collisions) {
    dem::step(model, s);
    begun += std::max<std::int64_t>(0, s.counters.contacts - previous);
    previous = s.counters.contacts;
  }
  return begun;
}

}  // namespace

TEST(Conservation, ElasticGasKeepsItsEnergy) {
  const dem::ModelSpec spec = gas_spec(true);
  dem::State s = gas(300, 3, 0.5);
  const dem::Model model = dem::compile_model(spec, s, "gas");
  dem::initialize(model, s);
  const double e0 = dem::kinetic_energy(s) + dem::elastic_energy(model, s);
  const std::int64_t collisions = run_counting_collisions(model, s, 1000);
  // Measured when no contact is active, so that no energy sits in a spring.
  while (s.counters.contacts + s.counters.wall_contacts > 0) dem::step(model, s);
  const double e1 = dem::kinetic_energy(s);
  EXPECT_GE(collisions, 1000);
  EXPECT_LT(std::abs(e1 - e0) / e0, 1e-4) << "after " << collisions << " collisions";
}

TEST(Conservation, CollisionsConserveMomentum) {
  // No walls, no gravity: grains fly through each other's paths; every collision exchanges
  // equal and opposite impulses.
  dem::ModelSpec spec = gas_spec(false);
  spec.domain.lo = Vec3::Constant(-1);
  spec.domain.hi = Vec3::Constant(1);
  dem::State s = gas(300, 5, 0.5);
  const dem::Model model = dem::compile_model(spec, s, "gas");
  dem::initialize(model, s);
  auto momentum = [&] {
    Vec3 p = Vec3::Zero();
    double scale = 0;
    for (std::size_t i = 0; i < s.size(); ++i) p += s.mass[i] * s.v[i], scale += s.mass[i] * s.v[i].norm();
    return std::pair{p, scale};
  };
  const auto [p0, scale] = momentum();
  std::int64_t contacts = 0;
  for (int n = 0; n < 3000; ++n) {
    dem::step(model, s);
    contacts += s.counters.contacts;
    EXPECT_LT((momentum().first - p0).norm() / scale, 1e-14) << "step " << n;
  }
  EXPECT_GT(contacts, 0);
}

TEST(Reproducibility, ThreadCountDoesNotChangeTheState) {
  const dem::ModelSpec spec = gas_spec(true);
  auto run = [&](int threads) {
    omp_set_num_threads(threads);
    dem::State s = gas(400, 9, 0.3);
    dem::ModelSpec with_gravity = spec;
    with_gravity.gravity = Vec3(0, 0, -9.81);
    with_gravity.materials[0].sliding_friction = 0.4;
    with_gravity.law.tangential = "mindlin";
    const dem::Model model = dem::compile_model(with_gravity, s, "gas");
    dem::initialize(model, s);
    for (int n = 0; n < 2000; ++n) dem::step(model, s);
    return dem::state_hash(s);
  };
  const int all = omp_get_max_threads();
  const std::string one = run(1), two = run(2), many = run(std::max(3, all));
  omp_set_num_threads(all);
  EXPECT_EQ(one, two);
  EXPECT_EQ(one, many);
}

// The mesh-wall branch of the wall stage on several threads: grains thrown onto the ring die's
// table and into its bore while a plate sweeps across the table (a moving mesh wall), with
// friction and rolling resistance, give the same bits on 1 and 2 threads.
TEST(Reproducibility, MeshWallsGiveTheSameStateOnAnyThreadCount) {
  const double r = 0.6e-3;
  const geometry::TriMesh ring = mesh::bundled_die("ring");
  const mesh::ToolMesh tool = mesh::tool_from_cavity(ring, mesh::table_around(ring, 3e-3), "ring");
  dem::ModelSpec spec = test::spec_with({test::glass(0.5, 0.4), test::rigid_wall(0.5, 0.3)}, Vec3(0, 0, -9.81));
  spec.materials[0].rolling_friction = spec.materials[1].rolling_friction = 0.1;
  spec.law.rolling = "epsd";
  spec.meshes.push_back(dem::fixed_mesh_wall(test::wall_field_of(tool.mesh, r / 4), 1, "die"));
  dem::MeshWall plate = dem::fixed_mesh_wall(
      test::wall_field_of(mesh::box_solid(Vec3(-1e-3, -12e-3, 0.2e-3), Vec3(1e-3, 12e-3, 3.5e-3)), r / 4), 1, "plate");
  plate.motion.start_position = Vec3(-10.5e-3, 0, 0);
  plate.motion.start_velocity = Vec3(0.5, 0, 0);
  spec.meshes.push_back(plate);
  auto run = [&](int threads) {
    omp_set_num_threads(threads);
    dem::State s;
    dem::InsertRegion region;
    region.box = {Vec3(-9e-3, -9e-3, 0.65e-3), Vec3(9e-3, 9e-3, 3e-3)};
    dem::InsertRequest req;
    req.count = 400;
    req.radius = r;
    req.radius_spread = 0.1;
    req.seed = 11;
    dem::insert_spheres(s, region, req);
    for (Vec3& v : s.v) v = Vec3(0, 0, -0.3);  // onto the table, the rim and into the bore
    const dem::Model model = dem::compile_model(spec, s, "pour");
    dem::initialize(model, s);
    std::int64_t wall_contacts = 0;
    for (int n = 0; n < 3000; ++n) {
      dem::step(model, s);
      wall_contacts += s.counters.wall_contacts;
    }
    EXPECT_GT(wall_contacts, 0);
    return dem::state_hash(s);
  };
  const int all = omp_get_max_threads();
  const std::string one = run(1), two = run(2);
  omp_set_num_threads(all);
  EXPECT_EQ(one, two);
}

TEST(Reproducibility, ResumedRunMatchesTheUninterruptedOne) {
  test::TempDir dir;
  dem::ModelSpec spec = gas_spec(true);
  spec.gravity = Vec3(0, 0, -9.81);
  spec.materials[0].sliding_friction = 0.4;
  spec.law.tangential = "mindlin";
  dem::State a = gas(300, 4, 0.3);
  const dem::Model model = dem::compile_model(spec, a, "gas");
  dem::initialize(model, a);
  for (int n = 0; n < 700; ++n) dem::step(model, a);
  // The run loop's maxima so far travel with the checkpoint (pipeline/run_loop.hpp): a resumed
  // run reports what happened before the stop too.
  a.loop_max_overlap_rel = 0.0625, a.loop_max_energy_gain = 0.125;
  dem::write_checkpoint(model, a, dir / "run.ckpt");
  for (int n = 0; n < 700; ++n) dem::step(model, a);
  dem::State b = dem::read_checkpoint(model, dir / "run.ckpt");
  EXPECT_EQ(b.loop_max_overlap_rel, 0.0625);
  EXPECT_EQ(b.loop_max_energy_gain, 0.125);
  for (int n = 0; n < 700; ++n) dem::step(model, b);
  EXPECT_EQ(dem::state_hash(a), dem::state_hash(b));
  dem::ModelSpec other = spec;
  other.materials[0].sliding_friction = 0.5;
  EXPECT_THROW(dem::read_checkpoint(dem::compile_model(other, b, "gas"), dir / "run.ckpt"), diefill::InputError);
}

// A checkpoint of an older format (the split one before clumps were split, DFCKSP01) is refused
// with what happened and what to do, not as "not a checkpoint".
TEST(Reproducibility, ACheckpointOfAnotherVersionIsRefusedAsSuch) {
  test::TempDir dir;
  dem::State s = gas(10, 2, 0.3);
  const dem::Model model = dem::compile_model(gas_spec(true), s, "gas");
  test::write_text(dir / "old.ckpt", "DFCKSP01" + model.hash + std::string(64, '\0'));
  try {
    dem::read_checkpoint(model, dir / "old.ckpt");
    ADD_FAILURE() << "the old checkpoint was read";
  } catch (const diefill::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("another version of diefill"), std::string::npos) << e.what();
  }
}

TEST(Insertion, FillsAClosedMeshWithoutOverlapsReproducibly) {
  const geometry::TriMesh ring = mesh::bundled_die("ring");
  mesh::SdfOptions o;
  o.voxel_m = 0.1e-3;
  o.exterior_band_m = 0.2e-3;
  o.interior_band_m = 0.5e-3;  // reaches the largest radius, 0.39 mm
  const auto field = std::make_shared<const geometry::WallField>(mesh::build_sdf(ring, o).wall_field(ring));
  auto fill = [&](std::uint64_t seed) {
    dem::State s;
    dem::InsertRegion region;
    region.box = {Vec3(-10e-3, -10e-3, -10e-3), Vec3(10e-3, 10e-3, 0)};
    region.inside = field;
    dem::InsertRequest req;
    req.count = 2000;
    req.radius = 0.3e-3;
    req.radius_spread = 0.3;
    req.seed = seed;
    EXPECT_EQ(dem::insert_spheres(s, region, req), 2000u);
    return s;
  };
  const dem::State a = fill(5), b = fill(5), c = fill(6);
  const mesh::ExactSurface exact(ring);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_LE(exact.signed_distance(a.x[i]), -a.radius[i] + 1e-12) << "inside the ring, clear of its walls";
    for (std::size_t j = i + 1; j < a.size(); ++j)
      ASSERT_GE((a.x[i] - a.x[j]).norm(), a.radius[i] + a.radius[j]) << i << " overlaps " << j;
  }
  EXPECT_EQ(a.x, b.x);
  EXPECT_NE(a.x, c.x);
}

namespace {

// A paddle (a 10 x 2 x 2 mm bar) spinning about the z axis through its middle, beside a grain at
// rest: only its rotation moves it.
dem::ModelSpec paddle_spec(double spin, double skin) {
  dem::ModelSpec spec = test::spec_with({test::glass(), test::rigid_wall()});
  dem::MeshWall paddle =
      dem::fixed_mesh_wall(test::wall_field_of(mesh::box_solid(Vec3(-5e-3, -1e-3, -1e-3), Vec3(5e-3, 1e-3, 1e-3)), 0.25e-3), 1, "paddle");
  paddle.motion.angular_velocity = Vec3(0, 0, spin);
  spec.meshes.push_back(paddle);
  spec.skin = skin;
  return spec;
}

}  // namespace

// A wall's rotation counts like its translation: in the neighbour list's rebuild trigger (its far
// end sweeps the skin without its origin moving) and in the refusal of a wall too fast for the skin.
TEST(RotatingWall, RotationTriggersRebuildsAndCountsInTheSpeedLimit) {
  dem::State s;
  s.add_sphere(0, Vec3(0, 0, 20e-3), 0.5e-3, 2500, 0);
  const double skin = 0.25e-3, spin = 10.0;  // the paddle's ends (5.1 mm out) move 51 mm/s
  const dem::Model model = dem::compile_model(paddle_spec(spin, skin), s, "paddle");
  dem::initialize(model, s);
  const std::int64_t builds = s.neighbours.builds;
  // Turning by 0.1 rad moves the far corner 0.51 mm: about four half-skins, four rebuilds.
  while (s.time < 0.1 / spin) dem::step(model, s);
  EXPECT_GE(s.neighbours.builds - builds, 3);
  // Fast enough that its ends cross half the skin in one step: refused, though its origin is still.
  EXPECT_THROW(dem::compile_model(paddle_spec(0.6 * skin / model.dt / 5.1e-3, skin), s, "paddle"), diefill::InputError);
}

// A checkpoint belongs to the walls' motion too: resumed under another motion, it is refused.
TEST(RotatingWall, CheckpointIsRefusedUnderAnotherMotion) {
  test::TempDir dir;
  dem::State s;
  s.add_sphere(0, Vec3(0, 0, 20e-3), 0.5e-3, 2500, 0);
  const dem::Model model = dem::compile_model(paddle_spec(10, 0.25e-3), s, "paddle");
  dem::initialize(model, s);
  for (int n = 0; n < 10; ++n) dem::step(model, s);
  dem::write_checkpoint(model, s, dir / "run.ckpt");
  EXPECT_NO_THROW(dem::read_checkpoint(model, dir / "run.ckpt"));
  EXPECT_THROW(dem::read_checkpoint(dem::compile_model(paddle_spec(11, 0.25e-3), s, "paddle"), dir / "run.ckpt"),
               diefill::InputError);
}
