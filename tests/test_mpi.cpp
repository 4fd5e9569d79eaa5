// The DEM split over MPI ranks (dem/mpi_exchange.hpp), run by CTest under mpirun on 1 to 4 and 8
// ranks: against the same scene run whole on every rank (the reference), forces and motion agree
// to rounding; no grain is lost or doubled at any step; momentum is conserved in free flight;
// the same rank count gives the same bits.
#include <fmt/core.h>
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <numbers>

#include "dem/bodies.hpp"
#include "dem/checkpoint.hpp"
#include "dem/distributed.hpp"
#include "dem/insert.hpp"
#include "dem/io.hpp"
#include "dem/mpi_exchange.hpp"
#include "dem/step.hpp"
#include "dem/walls.hpp"
#include "dem_support.hpp"
#include "mesh/shapes.hpp"
#include "mesh/tool.hpp"

using dem::Quat;
using dem::Vec3;

namespace {

int world_rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}
int world_size() {
  int n = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  return n;
}

// Frictional, rolling grains in a box of planes under gravity (or, for free flight, neither).
dem::ModelSpec box_spec(bool gravity_and_walls) {
  dem::ModelSpec spec = test::spec_with({test::glass(0.5, 0.4), test::rigid_wall(0.5, 0.3)},
                                        gravity_and_walls ? Vec3(0, 0, -9.81) : Vec3::Zero());
  spec.materials[0].rolling_friction = spec.materials[1].rolling_friction = 0.1;
  spec.law.rolling = "epsd";
  spec.max_impact_speed = 1.0;
  spec.domain.lo = Vec3::Constant(-8e-3);
  spec.domain.hi = Vec3::Constant(8e-3);
  if (gravity_and_walls)
    for (int a = 0; a < 3; ++a)
      for (int side : {-1, 1}) {
        Vec3 n = Vec3::Zero();
        n[a] = -side;
        spec.planes.push_back({Vec3::Unit(a) * side * 6e-3, n, 1, "box"});
      }
  return spec;
}

// A simple cubic lattice 2 % tighter than the grains (every grain touches its neighbours from
// the start), radii within ±2 %, random velocities.
dem::State compressed_lattice(int side, double speed) {
  dem::State s;
  dem::Random random(23);
  const double r = 0.25e-3, spacing = 1.96 * r, centre = 0.5 * (side - 1);
  for (int a = 0; a < side; ++a)
    for (int b = 0; b < side; ++b)
      for (int c = 0; c < side; ++c)
        s.add_sphere(std::int64_t(s.size()), spacing * Vec3(a - centre, b - centre, c - centre), r * random.uniform(0.98, 1.02), 2500, 0,
                     speed * Vec3(random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1)));
  return s;
}

dem::State pack(std::size_t count, double speed) {
  dem::State s;
  dem::InsertRegion region;
  region.box = {Vec3::Constant(-5.8e-3), Vec3::Constant(5.8e-3)};
  dem::InsertRequest req;
  req.count = count;
  req.radius = 0.25e-3;
  req.radius_spread = 0.2;
  req.seed = 21;
  dem::insert_spheres(s, region, req);
  dem::Random random(22);
  for (Vec3& v : s.v) v = speed * Vec3(random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1));
  return s;
}

// The same scene split: every rank starts with every ranks-th grain, so that nearly all of
// them migrate at the first build.
dem::State split(const dem::State& whole) { return dem::share_of(whole, dem::make_mpi_exchange()); }

std::map<std::int64_t, std::size_t> index_by_id(const dem::State& s) {
  std::map<std::int64_t, std::size_t> m;
  for (std::size_t i = 0; i < s.size(); ++i) m[s.id[i]] = i;
  return m;
}

// Every owned grain against the reference: position and velocity to rounding; force within one
// single-precision spacing (2^-23) of the largest force. The split sums in another order than the
// whole scene, so a spring may differ in its last bits and, stored in single precision
// (dem/types.hpp), round to the neighbouring value: a change of at most 2^-23 of a spring force,
// which is at most μ F_n, μ = 0.4 here. The 1e-12 of double rounding held before the springs were
// stored so; a spring lost or carried wrong changes a force by its whole size.
void expect_matches(const dem::State& part, const dem::State& whole, const char* when) {
  const auto reference = index_by_id(whole);
  double force_scale = 0, speed_scale = 0;
  for (std::size_t i = 0; i < whole.size(); ++i)
    force_scale = std::max(force_scale, whole.f[i].norm()), speed_scale = std::max(speed_scale, whole.v[i].norm());
  double worst_force = 0, worst_position = 0, worst_speed = 0;
  for (std::size_t i = 0; i < part.owned(); ++i) {
    const std::size_t k = reference.at(part.id[i]);
    worst_force = std::max(worst_force, (part.f[i] - whole.f[k]).norm() / force_scale);
    worst_position = std::max(worst_position, (part.x[i] - whole.x[k]).norm() / 6e-3);
    worst_speed = std::max(worst_speed, (part.v[i] - whole.v[k]).norm() / speed_scale);
  }
  EXPECT_LT(worst_force, 0x1p-23) << when << " on rank " << world_rank();
  EXPECT_LT(worst_position, 1e-12) << when << " on rank " << world_rank();
  EXPECT_LT(worst_speed, 1e-12) << when << " on rank " << world_rank();
}

// Grains counted over the ranks, and every id held by exactly one rank.
void expect_every_grain_once(const dem::State& part, std::size_t count) {
  std::vector<std::int64_t> mine(part.id.begin(), part.id.begin() + std::ptrdiff_t(part.owned()));
  int n = int(mine.size());
  std::vector<int> counts(static_cast<std::size_t>(world_size())), at(static_cast<std::size_t>(world_size()), 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
  for (std::size_t r = 1; r < counts.size(); ++r) at[r] = at[r - 1] + counts[r - 1];
  std::vector<std::int64_t> all(std::size_t(at.back() + counts.back()));
  MPI_Allgatherv(mine.data(), n, MPI_INT64_T, all.data(), counts.data(), at.data(), MPI_INT64_T, MPI_COMM_WORLD);
  ASSERT_EQ(all.size(), count);
  std::sort(all.begin(), all.end());
  EXPECT_EQ(std::adjacent_find(all.begin(), all.end()), all.end()) << "a grain on two ranks";
}

// Every grain's force by id, on every rank.
std::map<std::int64_t, Vec3> forces_by_id(const dem::State& part) {
  struct IdForce {
    std::int64_t id;
    double f[3];
  };
  std::vector<IdForce> mine;
  for (std::size_t i = 0; i < part.owned(); ++i) mine.push_back({part.id[i], {part.f[i].x(), part.f[i].y(), part.f[i].z()}});
  const int n = int(mine.size() * sizeof(IdForce));
  std::vector<int> counts(static_cast<std::size_t>(world_size())), at(static_cast<std::size_t>(world_size()), 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
  for (std::size_t r = 1; r < counts.size(); ++r) at[r] = at[r - 1] + counts[r - 1];
  std::vector<IdForce> all(std::size_t(at.back() + counts.back()) / sizeof(IdForce));
  MPI_Allgatherv(mine.data(), n, MPI_BYTE, all.data(), counts.data(), at.data(), MPI_BYTE, MPI_COMM_WORLD);
  std::map<std::int64_t, Vec3> by_id;
  for (const IdForce& g : all) by_id[g.id] = Vec3(g.f[0], g.f[1], g.f[2]);
  return by_id;
}

// What a resumed run must reproduce: the kinetic energy and the mean height of the grains.
std::pair<double, double> statistics(const dem::State& part) {
  double z = 0;
  for (std::size_t i = 0; i < part.owned(); ++i) z += part.x[i].z();
  const auto grains = double(part.exchange->sum(std::int64_t(part.owned())));
  return {part.exchange->sum(dem::kinetic_energy(part)), part.exchange->sum(z) / grains};
}

void expect_same_forces(const std::map<std::int64_t, Vec3>& a, const std::map<std::int64_t, Vec3>& b, const char* when) {
  ASSERT_EQ(a.size(), b.size()) << when;
  double scale = 0, worst = 0;
  for (const auto& [id, f] : a) scale = std::max(scale, f.norm());
  for (const auto& [id, f] : a) worst = std::max(worst, (f - b.at(id)).norm() / scale);
  EXPECT_LT(worst, 1e-12) << when;
}

// Four overlapping spheres of radius r in a cross, longer along x than y (test_clump_dem.cpp):
// volume and moments of the spheres, overlaps counted twice, a stand-in for a grain mesh.
geometry::ClumpTemplate cross(double r) {
  geometry::ClumpTemplate t;
  const double v = 4.0 / 3.0 * std::numbers::pi * r * r * r;
  for (const Vec3& c : {Vec3(1.6 * r, 0, 0), Vec3(-1.6 * r, 0, 0), Vec3(0, 0.7 * r, 0), Vec3(0, -0.7 * r, 0)}) {
    t.spheres.push_back({c, r});
    t.mesh_volume_m3 += v;
    t.inertia_principal_per_density += v * (Vec3::Constant(0.4 * r * r + c.squaredNorm()) - c.cwiseProduct(c));
  }
  return t;
}

// Crosses of 0.25 mm spheres on a lattice 2 % tighter than they are (each touches its neighbours
// from the start), alike in orientation, thrown in random directions and spun: 1,920 clumps,
// 7,680 spheres.
dem::State clump_lattice(double speed) {
  dem::State s;
  dem::Random random(29);
  const double r = 0.25e-3;
  const geometry::ClumpTemplate t = cross(r);
  const Vec3 spacing = 0.98 * Vec3(5.2 * r, 3.4 * r, 2 * r);
  const int sides[3] = {8, 12, 20};
  for (int a = 0; a < sides[0]; ++a)
    for (int b = 0; b < sides[1]; ++b)
      for (int c = 0; c < sides[2]; ++c) {
        const Vec3 at = spacing.cwiseProduct(Vec3(a - 0.5 * (sides[0] - 1), b - 0.5 * (sides[1] - 1), c - 0.5 * (sides[2] - 1)));
        const Vec3 v = speed * Vec3(random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1));
        const Vec3 w = (speed / r) * Vec3(random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1));
        dem::add_clump(s, t, 1.0, std::int64_t(s.size()), at, Quat::Identity(), 2500, 0, v, w);
      }
  return s;
}

// The clump lattice in a box of planes, whole on every rank and split, both initialized.
struct ClumpScene {
  dem::ModelSpec spec = box_spec(true);
  dem::State whole = clump_lattice(0.3);
  dem::Model model = dem::compile_model(spec, whole, "mpi clumps");
  dem::State part = split(whole);
  ClumpScene() {
    dem::initialize(model, whole);
    dem::initialize(model, part);
  }
};

// Every rank's owned clumps against the whole scene's (which created them in the order of their
// first member's id): the count exact, every member owned with its body, centre and velocity to
// rounding.
void expect_bodies_match(const dem::State& part, const dem::State& whole, const char* when) {
  std::map<std::int64_t, std::size_t> reference;
  for (std::size_t b = 0; b < whole.bodies.size(); ++b)
    reference[whole.id[std::size_t(whole.bodies.member[std::size_t(whole.bodies.member_start[b])])]] = b;
  EXPECT_EQ(part.exchange->sum(std::int64_t(part.bodies.size())), std::int64_t(whole.bodies.size())) << when;
  double speed_scale = 0;
  for (const Vec3& v : whole.bodies.v) speed_scale = std::max(speed_scale, v.norm());
  double worst_position = 0, worst_speed = 0;
  for (std::size_t b = 0; b < part.bodies.size(); ++b) {
    for (std::int32_t k = part.bodies.member_start[b]; k < part.bodies.member_start[b + 1]; ++k)
      ASSERT_LT(std::size_t(part.bodies.member[std::size_t(k)]), part.owned()) << "a member held as a ghost " << when;
    const std::size_t w = reference.at(part.id[std::size_t(part.bodies.member[std::size_t(part.bodies.member_start[b])])]);
    worst_position = std::max(worst_position, (part.bodies.x[b] - whole.bodies.x[w]).norm() / 6e-3);
    worst_speed = std::max(worst_speed, (part.bodies.v[b] - whole.bodies.v[w]).norm() / speed_scale);
  }
  EXPECT_LT(worst_position, 1e-12) << when << " on rank " << world_rank();
  EXPECT_LT(worst_speed, 1e-12) << when << " on rank " << world_rank();
}

// Checkpoints of the split runs, one per rank count, where CTest keeps them
// (tests/CMakeLists.txt runs 1, 2, 3, 4 and 8 ranks in that order).
std::filesystem::path checkpoint_of(int ranks) {
  const char* dir = std::getenv("DIEFILL_MPI_CHECKPOINTS");
  return std::filesystem::path(dir ? dir : "mpi_checkpoints") / ("lattice-" + std::to_string(ranks) + "-ranks");
}

}  // namespace

// 5,832 grains of a compressed lattice spring apart and fall in a box of planes. For the first
// 60 steps, which take in the first rebuild (grains migrate with their springs), every owned
// grain's force is the whole scene's within 2^-23 of the largest force (expect_matches), its
// position and velocity to rounding; later the two runs part by the growth of rounding differences that any change of
// summation order starts (1e-11 of the largest force by step 400), so to step 400 the test
// counts grains only.
TEST(MpiSplit, ForcesAndMotionMatchTheWholeSceneAndNoGrainIsLostOrDoubled) {
  const dem::ModelSpec spec = box_spec(true);
  dem::State whole = compressed_lattice(18, 0.3);
  const dem::Model model = dem::compile_model(spec, whole, "mpi");
  dem::State part = split(whole);
  dem::initialize(model, whole);
  dem::initialize(model, part);
  if (world_size() > 1) EXPECT_GT(part.ghosts, 100u);
  else EXPECT_EQ(part.ghosts, 0u);
  expect_matches(part, whole, "after initialize");
  std::int64_t rebuilds_while_matched = 0, contacts = 0, rebuilds = 0, cuts = 0;
  dem::Exchange& exchange = *part.exchange;
  for (int n = 1; n <= 400; ++n) {
    dem::step(model, whole);
    const std::int64_t before = part.neighbours.builds, collectives = exchange.global_collectives(), cut = exchange.cuts();
    dem::step(model, part);
    if (n <= 60) rebuilds_while_matched += part.neighbours.builds - before;
    rebuilds += part.neighbours.builds - before, cuts += exchange.cuts() - cut;
    // One collective a step, a rebuild's included, unless the step cut the subdomains anew.
    if (exchange.cuts() == cut) {
      EXPECT_EQ(exchange.global_collectives() - collectives, 1) << "at step " << n;
    }
    contacts += part.exchange->sum(part.counters.contacts);
    if (n == 1 || n == 20 || n == 40 || n == 60) expect_matches(part, whole, ("after " + std::to_string(n) + " steps").c_str());
    if (n % 100 == 0) expect_every_grain_once(part, whole.size());
  }
  EXPECT_GE(rebuilds_while_matched, 1) << "grains migrated while the runs are compared";
  EXPECT_GT(rebuilds, cuts) << "rebuilds without a cut were counted";
  EXPECT_GT(contacts, 100000);
}

// The ring die as a mesh wall around a lattice of 0.3 mm grains that fills its cavity 2 % tighter
// than the grains and presses on its walls (up to a fifth of a radius): about 10^4 grains and a
// thousand wall contacts; the die at rest, or moving. Through 20 steps with a rebuild at the 10th,
// every owned grain's force (its pairs' and its wall contacts') is the whole scene's within 2^-23
// of the largest (expect_matches).
// (Later the runs part by the growth of rounding differences that a change of summation order
// starts: 1.6e-12 of the largest force by step 40 with the die moving.)
// Frictional, rolling grains of radius about r under gravity with the bundled ring die as a mesh
// wall (the table at z = 0, the cavity 10 mm deep between radii 5 and 10 mm).
dem::ModelSpec ring_spec(double r) {
  const geometry::TriMesh ring = mesh::bundled_die("ring");
  const mesh::ToolMesh tool = mesh::tool_from_cavity(ring, mesh::table_around(ring, 3e-3), "ring");
  dem::ModelSpec spec = test::spec_with({test::glass(0.5, 0.4), test::rigid_wall(0.5, 0.3)}, Vec3(0, 0, -9.81));
  spec.materials[0].rolling_friction = spec.materials[1].rolling_friction = 0.1;
  spec.law.rolling = "epsd";
  spec.max_impact_speed = 1.0;
  spec.domain = {Vec3(-14e-3, -14e-3, -12e-3), Vec3(14e-3, 14e-3, 16e-3)};
  spec.meshes.push_back(dem::fixed_mesh_wall(test::wall_field_of(tool.mesh, r / 2), 1, "ring"));
  return spec;
}

class MpiRingDie : public ::testing::TestWithParam<double> {};

TEST_P(MpiRingDie, ForcesMatchTheWholeScene) {
  const double r = 0.3e-3;
  dem::ModelSpec spec = ring_spec(r);
  spec.meshes.back().motion.start_velocity = Vec3(GetParam(), 0, 0);
  dem::State whole;
  whole.add_sphere(0, Vec3(0, 0, 5e-3), r, 2500, 0);  // for the walls' distance while the lattice is laid
  const dem::Model walls = dem::compile_model(spec, whole, "ring walls");
  whole = {};
  dem::Random random(31);
  const double spacing = 1.96 * r;
  for (double z = -10e-3 + 0.8 * r; z < -r; z += spacing)
    for (double y = -10e-3; y <= 10e-3; y += spacing)
      for (double x = -10e-3; x <= 10e-3; x += spacing)
        if (const Vec3 p(x, y, z); dem::wall_distance(walls, 0, p) > 0.8 * r && p.head<2>().norm() < 10.5e-3)
          whole.add_sphere(std::int64_t(whole.size()), p, r * random.uniform(0.99, 1.01), 2500, 0);
  ASSERT_GT(whole.size(), 9000u);
  const dem::Model model = dem::compile_model(spec, whole, "mpi ring");
  dem::State part = split(whole);
  dem::initialize(model, whole);
  dem::initialize(model, part);
  EXPECT_GT(part.exchange->sum(part.counters.wall_contacts), 500);
  expect_matches(part, whole, "after initialize");
  for (int n = 1; n <= 20; ++n) {
    if (n == 10) {  // a rebuild on every rank and in the whole scene: grains migrate with their histories
      whole.neighbours.x_at_build.clear();
      part.neighbours.x_at_build.clear();
    }
    const std::int64_t before = part.neighbours.builds;
    dem::step(model, whole);
    dem::step(model, part);
    if (n == 10) {
      EXPECT_EQ(part.neighbours.builds, before + 1);
    }
    if (n == 1 || n == 10 || n == 20) expect_matches(part, whole, ("after " + std::to_string(n) + " steps").c_str());
  }
  expect_every_grain_once(part, whole.size());
}
// At rest, and moving through the grains at 0.5 m/s, as the shoe does.
INSTANTIATE_TEST_SUITE_P(WallSpeeds, MpiRingDie, ::testing::Values(0.0, 0.5));

// A grain rolls on the floor of the box across the face between two subdomains: two equal blocks
// of grains rest apart on the floor, the grain between them, so that on two ranks the cut lies
// just past the grain, which rolls across it. Its tangential spring with the floor must migrate
// with it (carried without it, the force after the migration differs by its whole size). At every
// step its force is the whole scene's to 1e-12 of its size; on two ranks it did change rank while
// moving (on three and four the cuts fall elsewhere, and the forces are compared all the same).
TEST(MpiSplit, AGrainRollingAcrossASubdomainFaceKeepsItsSpring) {
  const dem::ModelSpec spec = box_spec(true);
  const double r = 0.25e-3, floor = -6e-3;
  dem::State whole;
  for (const double x0 : {-5.5e-3, 3e-3})
    for (int a = 0; a < 6; ++a)
      for (int b = 0; b < 8; ++b)
        whole.add_sphere(std::int64_t(whole.size()), Vec3(x0 + 2.05 * r * a, -4e-3 + 2.05 * r * b, floor + r), r, 2500, 0);
  const std::int64_t slider = std::int64_t(whole.size());
  // Rolling without slip: the floor's spring sticks (a sliding one sits at the Coulomb limit,
  // which a spring started afresh reaches again in one step).
  whole.add_sphere(slider, Vec3(-1.5e-3, 0, floor + r), r, 2500, 0, Vec3(0.3, 0, 0), Vec3(0, 0.3 / r, 0));
  const dem::Model model = dem::compile_model(spec, whole, "mpi slider");
  dem::State part = split(whole);
  dem::initialize(model, whole);
  dem::initialize(model, part);
  const auto owner_of_slider = [&] {
    double mine = -1;
    for (std::size_t i = 0; i < part.owned(); ++i)
      if (part.id[i] == slider) mine = world_rank();
    return int(part.exchange->max(mine));
  };
  const int first_owner = owner_of_slider();
  int steps_after_moving = -1;
  double worst = 0, speed_at_crossing = 0;
  // Until 100 steps after it changed rank (or 0.2 mm along, past any cut that it could cross).
  for (int n = 0; n < 20000 && steps_after_moving < 100; ++n) {
    dem::step(model, whole);
    dem::step(model, part);
    const std::size_t k = index_by_id(whole).at(slider);
    const std::map<std::int64_t, Vec3> forces = forces_by_id(part);
    worst = std::max(worst, (forces.at(slider) - whole.f[k]).norm() / whole.f[k].norm());
    if (steps_after_moving >= 0) ++steps_after_moving;
    else if (owner_of_slider() != first_owner) steps_after_moving = 0, speed_at_crossing = whole.v[k].norm();
    if (steps_after_moving < 0 && whole.x[k].x() > -1.3e-3) break;
  }
  if (world_size() == 2) {
    EXPECT_GE(steps_after_moving, 0) << "the grain never changed rank";
    EXPECT_GT(speed_at_crossing, 0.1) << "it crossed moving";
  }
  EXPECT_LT(worst, 1e-12);
}

// Memory is distributed, not replicated: 50,000 grains packed as densely as the settled packs of
// ../shared/bench/liggghts (a lattice 2 % tighter than the grains, in a cylinder as tall as it is
// wide) over four ranks: no rank holds more than 40 % of them, ghosts included, by its own count
// (the 50k LIGGGHTS pack itself measured 28.8 %: docs/MPI.md, "Over MPI ranks").
TEST(MpiSplit, FourRanksEachHoldAtMostFortyPercentOfFiftyThousandGrains) {
  const dem::ModelSpec spec = box_spec(false);
  const double r = 0.1e-3, spacing = 1.96 * r;
  dem::State whole;
  for (int a = -20; a < 20; ++a)
    for (int b = -20; b < 20; ++b)
      for (int c = -20; c < 20; ++c)
        if (std::hypot(a + 0.5, b + 0.5) < 20.0)
          whole.add_sphere(std::int64_t(whole.size()), spacing * Vec3(a + 0.5, b + 0.5, c + 0.5), r, 2500, 0);
  ASSERT_GT(whole.size(), 49000u);
  const dem::Model model = dem::compile_model(spec, whole, "mpi memory");
  dem::State part = split(whole);
  dem::initialize(model, part);
  const double share = double(part.size()) / double(whole.size());
  if (world_size() == 4) {
    EXPECT_LE(share, 0.40) << "rank " << world_rank() << " holds " << part.owned() << " grains and " << part.ghosts << " ghosts";
  }
  EXPECT_EQ(part.exchange->sum(std::int64_t(part.owned())), std::int64_t(whole.size()));
  if (world_rank() == 0) std::printf("%d ranks: rank 0 holds %.1f %% of the grains with its ghosts\n", world_size(), 100 * share);
}

// 10^4 grains poured into the ring die over 2, 3 and 4 ranks: at every step of the pour the
// ranks hold every grain once (count and id sums every step, every id every 100), none is lost,
// and the cavity fills.
TEST(MpiSplit, EveryGrainIsHeldOnceAtEveryStepOfAPourIntoTheRing) {
  if (world_size() == 1) GTEST_SKIP() << "one rank holds every grain";
  const double r = 0.25e-3;
  const dem::ModelSpec spec = ring_spec(r);
  dem::State whole;
  dem::InsertRegion region;
  region.box = {Vec3(-9.5e-3, -9.5e-3, 0.5e-3), Vec3(9.5e-3, 9.5e-3, 14e-3)};
  region.accept = [](const Vec3& p, double radius) {
    const double rho = p.head<2>().norm();
    return rho < 9.5e-3 - radius && rho > 5.5e-3 + radius;
  };
  dem::InsertRequest request;
  request.count = 10000;
  request.radius = r;
  request.radius_spread = 0.1;
  request.max_solid_fraction = 0.5;
  request.seed = 41;
  ASSERT_EQ(dem::insert_spheres(whole, region, request), 10000u);
  for (Vec3& v : whole.v) v = Vec3(0, 0, -1.0);
  const dem::Model model = dem::compile_model(spec, whole, "mpi pour");
  dem::State part = split(whole);
  dem::initialize(model, part);
  const auto n_grains = std::int64_t(whole.size());  // ids 0 to n - 1
  while (part.time < 0.016) {  // the highest grains have passed the table by then
    dem::step(model, part);
    // Every step the count and the sums of the ids and of their squares (a grain lost or
    // doubled changes them); every 100 steps every id, sorted.
    std::int64_t count = 0, ids = 0, squares = 0;
    for (std::size_t i = 0; i < part.owned(); ++i) ++count, ids += part.id[i], squares += part.id[i] * part.id[i];
    ASSERT_EQ(part.exchange->sum(count), n_grains) << "at step " << part.step;
    ASSERT_EQ(part.exchange->sum(ids), n_grains * (n_grains - 1) / 2) << "at step " << part.step;
    ASSERT_EQ(part.exchange->sum(squares), (n_grains - 1) * n_grains * (2 * n_grains - 1) / 6) << "at step " << part.step;
    if (part.step % 100 == 0) expect_every_grain_once(part, whole.size());
    if (::testing::Test::HasFailure()) break;
  }
  std::int64_t in_cavity = 0;
  for (std::size_t i = 0; i < part.owned(); ++i) in_cavity += part.x[i].z() < 0;
  EXPECT_EQ(part.exchange->sum(part.lost), 0);
  EXPECT_GT(part.exchange->sum(in_cavity), 5000) << "the pour reached the cavity";
}

TEST(MpiSplit, MomentumIsConservedInFreeFlight) {
  const dem::ModelSpec spec = box_spec(false);
  dem::State whole = pack(4000, 0.5);
  const dem::Model model = dem::compile_model(spec, whole, "mpi gas");
  dem::State part = split(whole);
  dem::initialize(model, part);
  const auto momentum = [&] {
    Vec3 p = Vec3::Zero();
    double scale = 0;
    for (std::size_t i = 0; i < part.owned(); ++i) p += part.mass[i] * part.v[i], scale += part.mass[i] * part.v[i].norm();
    return std::pair{Vec3(part.exchange->sum(p.x()), part.exchange->sum(p.y()), part.exchange->sum(p.z())),
                     part.exchange->sum(scale)};
  };
  const auto [p0, scale] = momentum();
  std::int64_t contacts = 0;
  for (int n = 0; n < 1000; ++n) {
    dem::step(model, part);
    contacts += part.counters.contacts;
  }
  EXPECT_EQ(part.exchange->sum(part.lost), 0);
  EXPECT_LT((momentum().first - p0).norm() / scale, 1e-13);
  EXPECT_GT(part.exchange->sum(contacts), 0);
  expect_every_grain_once(part, whole.size());
}

// A grain that starts outside the domain is lost before the grains move between ranks. Split, it
// was sent as a ghost to the rank across a cut and only then lost by its owner, and the grains
// it overlapped there stopped the run at its first step (`diefill bench ring-10k` under mpirun:
// a grain of the cached pack had rolled off the table's edge). A row of grains along x, apart,
// whose middle the cuts of two and four ranks pass through, and above the middle, just outside
// the domain's top, a grain that overlaps the row's two middle grains by 40 % of a radius: it is
// lost on every rank count as on one process, no step stops, and every force and motion is the
// whole scene's (the row falls freely: its grains touch nothing).
TEST(MpiSplit, AGrainOutsideTheDomainIsLostBeforeAnyRankSeesIt) {
  dem::ModelSpec spec = box_spec(false);
  spec.gravity = Vec3(0, 0, -9.81);  // forces and speeds to compare
  spec.domain.hi.z() = 0.3e-3;
  const double r = 0.25e-3;
  dem::State whole;
  for (int k = 0; k < 24; ++k) whole.add_sphere(k, Vec3((k - 11.5) * 2.1 * r, 0, 0), r, 2500, 0, Vec3::Zero());
  whole.add_sphere(24, Vec3(0, 0, spec.domain.hi.z() + 1e-6), r, 2500, 0, Vec3::Zero());
  const dem::Model model = dem::compile_model(spec, whole, "mpi outside");
  dem::State part = split(whole);
  dem::initialize(model, whole);
  dem::initialize(model, part);
  EXPECT_EQ(whole.lost, 1);
  EXPECT_EQ(part.exchange->sum(part.lost), 1);
  for (int n = 1; n <= 5; ++n) {
    dem::step(model, whole);
    EXPECT_EQ(dem::step(model, part).status, dem::StepStatus::ok) << "at step " << n;
  }
  expect_matches(part, whole, "after 5 steps");
}

// Clumps split over ranks: each lives whole on the rank that owns its body's centre, its members'
// contacts with other ranks' clumps through ghosts. 1,920 crosses spring apart in a box; through
// 60 steps, which take in a rebuild (clumps migrate with their members' springs), every member's
// force is the whole scene's within 2^-23 of the largest, every body's centre and velocity to
// rounding, every clump held once; gathered on rank 0, the bodies are the whole scene's.
TEST(MpiSplit, ClumpsLiveWholeOnOneRankAndMatchTheWholeScene) {
  ClumpScene scene;
  const dem::Model& model = scene.model;
  dem::State &whole = scene.whole, &part = scene.part;
  if (world_size() > 1) {
    EXPECT_GT(part.ghosts, 100u);
  }
  expect_matches(part, whole, "after initialize");
  expect_bodies_match(part, whole, "after initialize");
  std::int64_t rebuilds = 0, contacts = 0;
  for (int n = 1; n <= 60; ++n) {
    dem::step(model, whole);
    const std::int64_t before = part.neighbours.builds;
    dem::step(model, part);
    rebuilds += part.neighbours.builds - before;
    contacts += part.exchange->sum(part.counters.contacts);
    if (n % 20 == 0) {
      const std::string when = "after " + std::to_string(n) + " steps";
      expect_matches(part, whole, when.c_str());
      expect_bodies_match(part, whole, when.c_str());
    }
  }
  EXPECT_GE(rebuilds, 1) << "clumps migrated while the runs are compared";
  EXPECT_GT(contacts, 10000);
  expect_every_grain_once(part, whole.size());
  const dem::State all = dem::gathered(part);
  if (world_rank() == 0) {
    ASSERT_EQ(all.bodies.size(), whole.bodies.size());
    double worst = 0;
    for (std::size_t b = 0; b < all.bodies.size(); ++b) {
      worst = std::max(worst, (all.bodies.x[b] - whole.bodies.x[b]).norm() / 6e-3);
      EXPECT_EQ(all.id[std::size_t(all.bodies.member[std::size_t(all.bodies.member_start[b])])],
                whole.id[std::size_t(whole.bodies.member[std::size_t(whole.bodies.member_start[b])])]);
    }
    EXPECT_LT(worst, 1e-12);
  }
}

// A split clump run checkpointed and resumed on this rank count, and a single process's clump
// checkpoint resumed split: one step after each, every member's force is that of the run that
// wrote it, stepped on, within 1e-12 of the largest (bodies, members and springs came back).
TEST(MpiCheckpoint, ClumpsResumeWithTheSameForces) {
  ClumpScene scene;
  const dem::Model& model = scene.model;
  dem::State &whole = scene.whole, &part = scene.part;
  for (int n = 0; n < 50; ++n) dem::step(model, whole), dem::step(model, part);
  const std::filesystem::path folder = checkpoint_of(world_size()).concat("-clumps");
  if (world_rank() == 0) {
    std::filesystem::create_directories(folder);
    dem::write_checkpoint(model, whole, folder / "whole.bin");
  }
  dem::write_checkpoint(model, part, folder / "split.bin");
  dem::step(model, part);
  dem::step(model, whole);
  std::map<std::int64_t, Vec3> after_whole;
  for (std::size_t i = 0; i < whole.size(); ++i) after_whole[whole.id[i]] = whole.f[i];
  const std::pair<const char*, std::map<std::int64_t, Vec3>> runs[] = {{"split.bin", forces_by_id(part)}, {"whole.bin", after_whole}};
  for (const auto& [file, expected] : runs) {
    dem::State resumed = dem::read_checkpoint(model, folder / file, dem::make_mpi_exchange());
    EXPECT_EQ(resumed.exchange->sum(std::int64_t(resumed.bodies.size())), std::int64_t(whole.bodies.size())) << file;
    dem::step(model, resumed);
    expect_same_forces(expected, forces_by_id(resumed), file);
  }
}

// Every rank writes its own grains: one particles CSV (rank after rank) and a .pvtu with a VTU
// piece per rank. After a rebuild (grains migrated), the CSV and the pieces together hold every
// grain once, with the whole scene's positions.
TEST(MpiSplit, EveryRankWritesItsOwnGrainsIntoOneCsvAndTheVtuPieces) {
  const dem::ModelSpec spec = box_spec(true);
  dem::State whole = compressed_lattice(12, 0.3);
  const dem::Model model = dem::compile_model(spec, whole, "mpi");
  dem::State part = split(whole);
  dem::initialize(model, part);
  const std::filesystem::path folder = checkpoint_of(world_size()).concat("-outputs");
  if (world_rank() == 0) std::filesystem::create_directories(folder);
  MPI_Barrier(MPI_COMM_WORLD);
  dem::write_particles_csv(part, folder / "particles.csv");
  const std::filesystem::path index = dem::write_vtu(part, folder / "snapshot.vtu");
  EXPECT_EQ(index.extension(), ".pvtu");
  if (world_rank() != 0) return;
  const auto expect_every_grain = [&](const dem::State& read, const char* what) {
    ASSERT_EQ(read.size(), whole.size()) << what;
    std::map<std::int64_t, Vec3> at;
    for (std::size_t i = 0; i < read.size(); ++i) at[read.id[i]] = read.x[i];
    ASSERT_EQ(at.size(), whole.size()) << what << ": an id twice";
    for (std::size_t i = 0; i < whole.size(); ++i) EXPECT_EQ(at[whole.id[i]], whole.x[i]) << what << ", grain " << whole.id[i];
  };
  expect_every_grain(dem::read_particles_csv(folder / "particles.csv", 0, 2500), "particles.csv");
  dem::State pieces;
  std::ifstream in(index);
  const std::string listed((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (int r = 0; r < world_size(); ++r) {
    const auto piece = folder / fmt::format("snapshot_r{}.vtu", r);
    EXPECT_NE(listed.find(piece.filename().string()), std::string::npos) << piece;
    const dem::State read = dem::read_particles_vtu(piece, 0, 2500);
    for (std::size_t i = 0; i < read.size(); ++i) pieces.add_sphere(read.id[i], read.x[i], read.radius[i], 2500, 0);
  }
  expect_every_grain(pieces, "the VTU pieces");
}

TEST(MpiSplit, TheSameRankCountGivesTheSameBits) {
  const dem::ModelSpec spec = box_spec(true);
  const auto run = [&] {
    dem::State whole = pack(3000, 0.3);
    const dem::Model model = dem::compile_model(spec, whole, "mpi");
    dem::State part = split(whole);
    dem::initialize(model, part);
    for (int n = 0; n < 300; ++n) dem::step(model, part);
    return dem::state_hash(part);
  };
  EXPECT_EQ(run(), run());
}

// A split run checkpointed at step 200 and resumed, by this rank count and by a run on another
// (one rank fewer, or DIEFILL_MPI_RESUME_FROM's; CTest ran it before): one step after the restart
// every grain's force is the uninterrupted run's within 1e-12 of the largest (positions, forces
// and every pair's and wall contact's history came back: a lost spring would change its grains'
// forces by its full size), and 200 steps after it the kinetic energy and the mean height are the
// uninterrupted run's to 1e-9; on its own rank count, the state is the uninterrupted run's, bit for bit.
TEST(MpiCheckpoint, AnyRankCountResumesWithTheSameForcesAndStatistics) {
  const dem::ModelSpec spec = box_spec(true);
  dem::State whole = compressed_lattice(18, 0.3);
  const dem::Model model = dem::compile_model(spec, whole, "mpi");
  dem::State part = split(whole);
  dem::initialize(model, part);
  for (int n = 0; n < 200; ++n) dem::step(model, part);
  const std::filesystem::path mine = checkpoint_of(world_size());
  if (world_rank() == 0) std::filesystem::create_directories(mine);
  dem::write_checkpoint(model, part, mine / "state.bin");
  dem::step(model, part);
  const std::map<std::int64_t, Vec3> after_checkpoint = forces_by_id(part);
  for (int n = 1; n < 200; ++n) dem::step(model, part);
  const auto [kinetic, height] = statistics(part);
  if (world_rank() == 0) {
    std::ofstream forces(mine / "forces.txt");
    forces.precision(17);
    for (const auto& [id, f] : after_checkpoint) forces << id << ' ' << f.x() << ' ' << f.y() << ' ' << f.z() << '\n';
    std::ofstream(mine / "statistics.txt") << std::hexfloat << kinetic << ' ' << height << '\n';
  }
  MPI_Barrier(MPI_COMM_WORLD);

  // Another rank count's checkpoint: DIEFILL_MPI_RESUME_FROM's (tests/CMakeLists.txt), or one rank fewer's.
  const char* other = std::getenv("DIEFILL_MPI_RESUME_FROM");
  for (const int writer : {world_size(), other ? std::atoi(other) : world_size() - 1}) {
    if (writer < 1) continue;
    const std::filesystem::path from = checkpoint_of(writer);
    ASSERT_TRUE(std::filesystem::exists(from / "statistics.txt"))
        << from << " is missing: CTest runs Mpi.Ranks" << writer << " first, which writes it";
    std::map<std::int64_t, Vec3> expected;
    std::ifstream forces(from / "forces.txt");
    for (std::int64_t id; forces >> id;) forces >> expected[id].x() >> expected[id].y() >> expected[id].z();
    std::ifstream stats(from / "statistics.txt");
    std::string kinetic_text, height_text;  // hexadecimal: exact
    stats >> kinetic_text >> height_text;
    const double expected_kinetic = std::strtod(kinetic_text.c_str(), nullptr);
    const double expected_height = std::strtod(height_text.c_str(), nullptr);

    const std::string when = "resuming the checkpoint of " + std::to_string(writer) + " ranks";
    dem::State resumed = dem::read_checkpoint(model, from / "state.bin", dem::make_mpi_exchange());
    EXPECT_EQ(resumed.step, 200);
    dem::step(model, resumed);
    expect_same_forces(expected, forces_by_id(resumed), when.c_str());
    for (int n = 1; n < 200; ++n) dem::step(model, resumed);
    expect_every_grain_once(resumed, whole.size());
    // Each rank restored its own piece as it was: the uninterrupted run's bits.
    if (writer == world_size()) {
      EXPECT_EQ(dem::state_hash(resumed), dem::state_hash(part)) << when << " on rank " << world_rank();
    }
    const auto [k, z] = statistics(resumed);
    EXPECT_NEAR(k, expected_kinetic, 1e-9 * expected_kinetic) << when;
    EXPECT_NEAR(z, expected_height, 1e-9 * 6e-3) << when;
  }
}

// Every transfer between ranks in messages of at most 700 bytes (make_mpi_exchange), as the
// gathers and migrations of tens of millions of grains go in pieces of 1 GiB; 700 divides no
// record, so that records straddle pieces. Split clumps, a face of them pressed by a plane, stepped
// through a forced rebuild (grains migrate with their springs and wall contacts, ghosts go and
// move every step): the state, the gathered whole state and the checkpoint are those of the same
// run in whole messages, bit for bit, and the checkpoint read back in pieces writes the same file.
TEST(MpiChunked, MessagesInPiecesGiveTheSameBits) {
  dem::ModelSpec spec = box_spec(true);
  spec.planes.push_back({Vec3(5.1e-3, 0, 0), Vec3(-1, 0, 0), 1, "press"});  // the lattice reaches 5.11 mm
  const dem::State whole = clump_lattice(0.3);
  const dem::Model model = dem::compile_model(spec, whole, "mpi pieces");
  dem::State in_whole = dem::share_of(whole, dem::make_mpi_exchange());
  dem::State in_pieces = dem::share_of(whole, dem::make_mpi_exchange(700));
  for (dem::State* s : {&in_whole, &in_pieces}) {
    dem::initialize(model, *s);
    for (int n = 1; n <= 30; ++n) {
      if (n == 15) s->neighbours.x_at_build.clear();
      dem::step(model, *s);
    }
  }
  EXPECT_EQ(dem::state_hash(in_pieces), dem::state_hash(in_whole)) << "on rank " << world_rank();
  EXPECT_GT(in_pieces.exchange->sum(std::int64_t(in_pieces.neighbours.near_wall.size())), 0) << "wall contacts travel";

  // The gathered states as single-process checkpoints: every per-grain array and every body, as bytes.
  const std::filesystem::path folder = checkpoint_of(world_size()).concat("-pieces");
  const auto write_gathered = [&](const dem::State& part, const char* file) {
    const dem::State all = dem::gathered(part);
    if (world_rank() == 0) {
      EXPECT_EQ(all.size(), whole.size()) << file;
      dem::write_checkpoint(model, all, folder / file);
    }
  };
  const auto bytes = [&](const std::filesystem::path& file) {
    std::ifstream in(folder / file, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  // This rank's piece of a split checkpoint (dem/checkpoint.hpp).
  const auto piece = [&](const char* file) { return fmt::format("{}.rank-{}-of-{}", file, world_rank(), world_size()); };
  write_gathered(in_whole, "gathered-whole.bin");
  write_gathered(in_pieces, "gathered-pieces.bin");
  dem::write_checkpoint(model, in_whole, folder / "split-whole.bin");
  dem::write_checkpoint(model, in_pieces, folder / "split-pieces.bin");
  const dem::State resumed = dem::read_checkpoint(model, folder / "split-pieces.bin", dem::make_mpi_exchange(700));
  write_gathered(resumed, "gathered-resumed.bin");
  dem::write_checkpoint(model, resumed, folder / "split-resumed.bin");
  // Every rank's piece of the checkpoints (the resumed run's too: the same rank count restores
  // its state as it was), and rank 0's index.
  const std::string split = bytes(piece("split-whole.bin"));
  EXPECT_GT(split.size(), in_whole.owned() * sizeof(dem::GrainRecord));
  EXPECT_TRUE(bytes(piece("split-pieces.bin")) == split) << "the checkpoint differs on rank " << world_rank();
  EXPECT_TRUE(bytes(piece("split-resumed.bin")) == split) << "the resumed state's checkpoint differs on rank " << world_rank();
  if (world_rank() == 0) {
    const std::string gathered = bytes("gathered-whole.bin");
    EXPECT_TRUE(bytes("gathered-pieces.bin") == gathered) << "the gathered state differs";
    EXPECT_TRUE(bytes("gathered-resumed.bin") == gathered) << "the gathered resumed state differs";
    EXPECT_TRUE(bytes("split-pieces.bin") == bytes("split-whole.bin")) << "the index differs";
    EXPECT_TRUE(bytes("split-resumed.bin") == bytes("split-whole.bin")) << "the resumed state's index differs";
  }
}

int main(int argc, char** argv) {
  int provided = 0;  // as diefill asks (cli/mpi_session.cpp)
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  ::testing::InitGoogleTest(&argc, argv);
  const int failed = RUN_ALL_TESTS();
  int any = 0;
  MPI_Allreduce(&failed, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  MPI_Finalize();
  return any;
}
