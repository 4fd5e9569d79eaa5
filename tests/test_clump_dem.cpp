// Rigid multi-sphere clumps (dem/bodies.hpp): free-body dynamics against theory (angular
// momentum, energy, the intermediate-axis flip), momentum through collisions, rest on a wall,
// rigidity, bit-identical results across thread counts and checkpoints, and the particles CSV.
#include <gtest/gtest.h>
#include <omp.h>

#include <chrono>
#include <cstring>
#include <cmath>
#include <fstream>
#include <numbers>
#include <optional>

#include "core/base64.hpp"
#include "core/error.hpp"
#include "dem/bodies.hpp"
#include "dem/checkpoint.hpp"
#include "dem/forces.hpp"
#include "dem/insert.hpp"
#include "dem/io.hpp"
#include "dem_support.hpp"
#include "support.hpp"

using dem::Quat;
using dem::Vec3;

namespace {

// Volume and principal moments of unit-density solid spheres at `centres`, overlaps counted
// twice: a stand-in for a grain mesh. The layouts below are symmetric, so the moments about
// x, y, z are the principal ones.
geometry::ClumpTemplate template_of(const std::vector<Vec3>& centres, double r) {
  geometry::ClumpTemplate t;
  const double v = 4.0 / 3.0 * std::numbers::pi * r * r * r;
  for (const Vec3& c : centres) {
    t.spheres.push_back({c, r});
    t.mesh_volume_m3 += v;
    t.inertia_principal_per_density += v * (Vec3::Constant(0.4 * r * r + c.squaredNorm()) - c.cwiseProduct(c));
  }
  return t;
}

// Four overlapping spheres in a cross longer along x than y: I1 < I2 < I3 about x, y, z.
geometry::ClumpTemplate cross(double r = 0.5e-3) {
  return template_of({Vec3(1.6 * r, 0, 0), Vec3(-1.6 * r, 0, 0), Vec3(0, 0.7 * r, 0), Vec3(0, -0.7 * r, 0)}, r);
}

dem::State one_clump(const geometry::ClumpTemplate& t, const Quat& q, const Vec3& x, const Vec3& w_body) {
  dem::State s;
  dem::add_clump(s, t, 1.0, 0, x, q, 2500, 0, Vec3::Zero(), q * w_body);
  return s;
}

// No gravity, no walls; the time step is automatic when not given.
dem::ModelSpec free_space(std::optional<double> dt = std::nullopt) {
  dem::ModelSpec spec = test::spec_with({test::glass(1.0, 0.0)});
  spec.time_step = dt;
  spec.domain.lo = Vec3::Constant(-1);
  spec.domain.hi = Vec3::Constant(1);
  return spec;
}

// Body-frame angular velocity of body b.
Vec3 body_spin(const dem::State& s, std::size_t b) {
  return s.bodies.q[b].conjugate() * s.bodies.angular_velocity(b);
}

// ½ ωᵀ I ω with ω recomputed from the orientation and the body-frame moments.
double rotational_energy(const dem::State& s, std::size_t b) {
  const Vec3 w = body_spin(s, b);
  return 0.5 * w.dot(s.bodies.inertia[b].cwiseProduct(w));
}

// A few grains leave nothing to share between threads but the cost of their barriers, which a
// busy machine makes a thousand times that of the work.
struct OneThread {
  int before = omp_get_max_threads();
  OneThread() { omp_set_num_threads(1); }
  ~OneThread() { omp_set_num_threads(before); }
};

Vec3 total_angular_momentum(const dem::State& s) {
  Vec3 l = Vec3::Zero();
  for (std::size_t b = 0; b < s.bodies.size(); ++b)
    l += s.bodies.mass[b] * s.bodies.x[b].cross(s.bodies.v[b]) + s.bodies.l[b];
  return l;
}

dem::ModelSpec box_spec(double half_width, double height) {
  dem::ModelSpec spec = test::spec_with({test::glass(0.5, 0.4), test::rigid_wall(0.5, 0.4)}, Vec3(0, 0, -9.81));
  spec.max_impact_speed = 0.5;
  spec.domain.lo = Vec3(-2 * half_width, -2 * half_width, -1e-3);
  spec.domain.hi = Vec3(2 * half_width, 2 * half_width, 2 * height);
  spec.planes.push_back({Vec3::Zero(), Vec3::UnitZ(), 1, "floor"});
  for (int a = 0; a < 2; ++a)
    for (int side : {-1, 1}) {
      Vec3 n = Vec3::Zero();
      n[a] = -side;
      spec.planes.push_back({Vec3::Unit(a) * side * half_width, n, 1, "side"});
    }
  return spec;
}

// Clumps in a box, thrown in random directions at up to `speed` and spun.
dem::State clump_pack(const geometry::ClumpTemplate& t, std::size_t count, double half_width, double height,
                      std::uint64_t seed, double speed = 0) {
  dem::State s;
  dem::InsertRegion region;
  region.box = {Vec3(-half_width, -half_width, 0), Vec3(half_width, half_width, height)};
  EXPECT_EQ(dem::insert_clumps(s, region, t, 1.0, count, 0, 2500, seed), count);
  dem::Random random(seed + 1);
  for (std::size_t b = 0; b < s.bodies.size(); ++b) {
    s.bodies.v[b] = speed * Vec3(random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1));
    s.bodies.l[b] = s.bodies.mass[b] * t.spheres[0].radius * s.bodies.v[b].cross(Vec3::UnitZ());
  }
  dem::place_members(s);
  return s;
}

}  // namespace

TEST(FreeClump, KeepsItsAngularMomentumAndEnergy) {
  const OneThread one_thread;
  const dem::ModelSpec spec = free_space(3e-6);
  dem::State s = one_clump(cross(), Quat(0.9, 0.1, -0.3, 0.2).normalized(), Vec3::Zero(), Vec3(120, -75, 180));
  const dem::Model model = dem::compile_model(spec, s, "free clump");
  dem::initialize(model, s);
  // From the members' spins and the orientation, not from the stored momentum.
  auto momentum = [&] {
    const Quat q = s.bodies.q[0];
    return Vec3(q * s.bodies.inertia[0].cwiseProduct(q.conjugate() * s.w[0]));
  };
  const Vec3 l0 = momentum();
  const double e0 = rotational_energy(s, 0);
  double worst_l = 0, worst_e = 0;
  for (int n = 0; n < 100000; ++n) {
    dem::step(model, s);
    if (n % 100 == 0) {
      worst_l = std::max(worst_l, (momentum() - l0).norm() / l0.norm());
      worst_e = std::max(worst_e, std::abs(rotational_energy(s, 0) - e0) / e0);
    }
  }
  std::printf("free clump over 1e5 steps: |ΔL|/|L| %.3g, |ΔE|/E %.3g\n", worst_l, worst_e);
  EXPECT_LT(worst_l, 1e-6);
  EXPECT_LT(worst_e, 1e-5);
  EXPECT_EQ(s.counters.contacts, 0);
}

TEST(FreeClump, FlipsAboutItsIntermediateAxisOnly) {
  const OneThread one_thread;
  const geometry::ClumpTemplate t = cross();
  const Vec3 I = t.inertia_principal_per_density;
  ASSERT_LT(I[0], I[1]);
  ASSERT_LT(I[1], I[2]);
  const double spin = 300, eps = 1e-2 * spin, dt = 3e-6;
  // Growth rate of a perturbation of an intermediate-axis spin (Euler's equations, linearised).
  const double rate = spin * std::sqrt((I[1] - I[0]) * (I[2] - I[1]) / (I[0] * I[2]));
  const int steps = int(4 * std::log(spin / eps) / rate / dt);
  const dem::ModelSpec spec = free_space(dt);
  for (int axis = 0; axis < 3; ++axis) {
    Vec3 w = Vec3::Constant(eps);
    w[axis] = spin;
    dem::State s = one_clump(t, Quat::Identity(), Vec3::Zero(), w);
    const dem::Model model = dem::compile_model(spec, s, "spinning clump");
    dem::initialize(model, s);
    double lowest = 1, flip = -1;
    for (int n = 0; n < steps; ++n) {
      dem::step(model, s);
      const double along = body_spin(s, 0)[axis] / spin;
      lowest = std::min(lowest, along);
      if (along < 0 && flip < 0) flip = s.time;
    }
    std::printf("spin about axis %d: lowest ω/ω0 %.4f, reversed at t = %.4g s (linear theory e-folds in %.4g s)\n",
                axis + 1, lowest, flip, 1 / rate);
    if (axis == 1) {
      EXPECT_GT(flip, 0) << "the intermediate-axis spin must reverse";
    } else {
      EXPECT_GT(lowest, 0.97) << "a spin about axis " << axis + 1 << " is stable";
    }
  }
}

TEST(ClumpCollisions, ConserveMomentumAndAngularMomentum) {
  const OneThread one_thread;
  // Two frictional clumps in free space, thrown off-centre at each other: every contact
  // force acts at one point on both, so the bodies' sums keep both momenta.
  dem::ModelSpec spec = free_space();
  spec.materials[0] = test::glass(0.6, 0.5);
  const geometry::ClumpTemplate t = cross();
  dem::State s;
  dem::add_clump(s, t, 1.0, 0, Vec3(-2.2e-3, 0.4e-3, 0), Quat(0.8, 0.2, 0.5, -0.1).normalized(), 2500, 0,
                 Vec3(0.3, 0, 0), Vec3(0, 0, 40));
  dem::add_clump(s, t, 1.0, 4, Vec3(2.2e-3, -0.3e-3, 0.2e-3), Quat(0.3, -0.6, 0.1, 0.7).normalized(), 2500, 0,
                 Vec3(-0.3, 0, 0), Vec3(30, 0, 0));
  const dem::Model model = dem::compile_model(spec, s, "collision");
  dem::initialize(model, s);
  auto momentum = [&] { return Vec3(s.bodies.mass[0] * s.bodies.v[0] + s.bodies.mass[1] * s.bodies.v[1]); };
  const Vec3 p0 = momentum(), l0 = total_angular_momentum(s);
  const double p_scale = s.bodies.mass[0] * s.bodies.v[0].norm() * 2, l_scale = l0.norm() + p_scale * 2e-3;
  std::int64_t contacts = 0;
  double worst_p = 0, worst_l = 0;
  for (int n = 0; n < 20000; ++n) {
    dem::step(model, s);
    contacts += s.counters.contacts;
    worst_p = std::max(worst_p, (momentum() - p0).norm() / p_scale);
    worst_l = std::max(worst_l, (total_angular_momentum(s) - l0).norm() / l_scale);
  }
  std::printf("collision: %lld contact steps, |Δp| %.3g, |ΔL| %.3g (relative)\n", (long long)contacts, worst_p, worst_l);
  EXPECT_GT(contacts, 0);
  EXPECT_LT(worst_p, 1e-12);
  EXPECT_LT(worst_l, 1e-12);
}

TEST(ClumpOnAWall, ComesToRestWithoutCreeping) {
  const OneThread one_thread;
  dem::ModelSpec spec = test::spec_with({test::glass(0.5, 0.5), test::rigid_wall(0.5, 0.5)}, Vec3(0, 0, -9.81));
  spec.max_impact_speed = 0.5;
  spec.planes.push_back({Vec3::Zero(), Vec3::UnitZ(), 1, "floor"});
  dem::State s = one_clump(cross(), Quat(0.9, 0.3, -0.2, 0.4).normalized(), Vec3(0, 0, 3e-3), Vec3(20, 0, -10));
  const dem::Model model = dem::compile_model(spec, s, "drop");
  dem::initialize(model, s);
  double impact = 0;
  while (s.counters.wall_contacts == 0) {
    impact = dem::kinetic_energy(s);
    dem::step(model, s);
  }
  const int steps = int(0.4 / model.dt);
  Vec3 late = Vec3::Zero();
  for (int n = 0; n < steps; ++n) {
    ASSERT_EQ(dem::step(model, s).status, dem::StepStatus::ok);
    if (n == steps * 3 / 4) late = s.bodies.x[0];
  }
  const double ratio = dem::kinetic_energy(s) / impact;
  const double creep = (s.bodies.x[0] - late).norm();
  std::printf("drop: impact energy %.4g J, rest/impact %.3g, centre moved %.3g m over the last 0.1 s, %lld wall contacts\n",
              impact, ratio, creep, (long long)s.counters.wall_contacts);
  EXPECT_LT(ratio, 1e-9);
  EXPECT_LT(creep, 1e-9);
  EXPECT_GE(s.counters.wall_contacts, 3) << "a flat cross rests on three or four members";
}

TEST(ClumpRigidity, OverlappingMembersExertNoForceOnEachOther) {
  const OneThread one_thread;
  dem::State s = one_clump(cross(), Quat(0.6, -0.2, 0.7, 0.3).normalized(), Vec3(1e-3, 2e-3, -1e-3), Vec3::Zero());
  const dem::Model model = dem::compile_model(free_space(1e-6), s, "rigid clump");
  dem::initialize(model, s);
  const dem::Array<Vec3> x0 = s.x;
  const Vec3 centre = s.bodies.x[0];
  for (int n = 0; n < 1000; ++n) dem::step(model, s);
  EXPECT_TRUE(s.neighbours.partner.empty()) << "no pair of one clump is listed";
  EXPECT_EQ(s.counters.contacts, 0);
  EXPECT_EQ(dem::elastic_energy(model, s), 0.0);
  EXPECT_EQ(s.bodies.x[0], centre);
  EXPECT_EQ(s.bodies.v[0], Vec3::Zero());
  EXPECT_EQ(s.bodies.l[0], Vec3::Zero());
  for (std::size_t i = 0; i < s.size(); ++i) {
    EXPECT_EQ(s.f[i], Vec3::Zero());
    EXPECT_EQ(s.v[i], Vec3::Zero());
  }
  EXPECT_EQ(s.x, x0);
}

TEST(ClumpInsertion, PlacesClumpsWithoutOverlapsReproducibly) {
  const geometry::ClumpTemplate t = cross(0.3e-3);
  const dem::State a = clump_pack(t, 200, 6e-3, 14e-3, 3), b = clump_pack(t, 200, 6e-3, 14e-3, 3),
                   c = clump_pack(t, 200, 6e-3, 14e-3, 4);
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = i + 1; j < a.size(); ++j) {
      if (a.body[i] == a.body[j]) continue;
      ASSERT_GE((a.x[i] - a.x[j]).norm(), a.radius[i] + a.radius[j]) << i << " overlaps " << j;
    }
  EXPECT_EQ(a.x, b.x);
  EXPECT_NE(a.x, c.x);
  // Orientations spread over all rotations: the body x axes average to nearly nothing.
  Vec3 mean = Vec3::Zero();
  for (const Quat& q : a.bodies.q) mean += q * Vec3::UnitX() / double(a.bodies.size());
  EXPECT_LT(mean.norm(), 0.15);
  EXPECT_DOUBLE_EQ(a.bodies.mass[0], 2500 * t.mesh_volume_m3) << "the grain's mass, not the spheres'";
  dem::State none;
  geometry::ClumpTemplate no_grain = t;
  no_grain.mesh_volume_m3 = 0;
  EXPECT_THROW(dem::add_clump(none, no_grain, 1.0, 0, Vec3::Zero(), Quat::Identity(), 2500, 0), diefill::InputError);
}

TEST(ClumpReproducibility, ThreadCountAndCheckpointDoNotChangeTheState) {
  test::TempDir dir;
  const dem::ModelSpec spec = box_spec(6e-3, 12e-3);
  auto run = [&](int threads, bool checkpoint) {
    omp_set_num_threads(threads);
    dem::State s = clump_pack(cross(0.3e-3), 150, 6e-3, 12e-3, 7, 0.5);
    const dem::Model model = dem::compile_model(spec, s, "pack");
    dem::initialize(model, s);
    std::int64_t contacts = 0;
    for (int n = 0; n < 2500; ++n) dem::step(model, s), contacts += s.counters.contacts + s.counters.wall_contacts;
    if (checkpoint) {
      dem::write_checkpoint(model, s, dir / "pack.ckpt");
      s = dem::read_checkpoint(model, dir / "pack.ckpt");
    }
    for (int n = 0; n < 2500; ++n) dem::step(model, s), contacts += s.counters.contacts + s.counters.wall_contacts;
    EXPECT_GT(contacts, 1000) << "grains collide with each other and the walls";
    return dem::state_hash(s);
  };
  const int all = omp_get_max_threads();
  const std::string one = run(1, false), two = run(2, false), resumed = run(2, true);
  omp_set_num_threads(all);
  EXPECT_EQ(one, two);
  EXPECT_EQ(one, resumed);
}

TEST(ClumpFiles, CsvAndSnapshotNameTheBodyAndTheCsvIsRefusedOnInput) {
  test::TempDir dir;
  dem::State s = one_clump(cross(), Quat(0.6, -0.2, 0.7, 0.3).normalized(), Vec3::Zero(), Vec3::Zero());
  s.add_sphere(99, Vec3(0, 0, 5e-3), 0.5e-3, 2500, 0);
  dem::write_particles_csv(s, dir / "p.csv");
  std::ifstream in(dir / "p.csv");
  std::string header, member, sphere;
  std::getline(in, header);
  std::getline(in, member);
  for (std::string line; std::getline(in, line);) sphere = line;
  EXPECT_EQ(header, "id,x,y,z,vx,vy,vz,wx,wy,wz,radius,density,body,qw,qx,qy,qz");
  EXPECT_NE(member.find(",2500,0,"), std::string::npos) << member;
  EXPECT_TRUE(sphere.ends_with(",-1,1,0,0,0")) << sphere;
  EXPECT_THROW(dem::read_particles_csv(dir / "p.csv", 0, 2500), diefill::InputError);
  // Snapshots name a clump by its first member's id (a binary array: a UInt64 byte count, then
  // the Int64 ids).
  dem::write_vtu(s, dir / "p.vtu");
  std::ifstream vtu(dir / "p.vtu");
  const std::string text((std::istreambuf_iterator<char>(vtu)), std::istreambuf_iterator<char>());
  const std::size_t begin = text.find('>', text.find("Name=\"body\"")) + 1;
  std::vector<std::uint8_t> bytes;
  ASSERT_TRUE(diefill::base64_decode(std::string_view(text).substr(begin, text.find("</DataArray>", begin) - begin), bytes));
  ASSERT_EQ(bytes.size(), 8u + 5 * 8);
  std::vector<std::int64_t> body(5);
  std::memcpy(body.data(), bytes.data() + 8, 5 * 8);
  EXPECT_EQ(body, (std::vector<std::int64_t>{0, 0, 0, 0, 99}));
  // Read back exactly (the arrays are binary), as `diefill density` reads a snapshot.
  const dem::State back = dem::read_particles_vtu(dir / "p.vtu", 0, 2500);
  ASSERT_EQ(back.size(), s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    EXPECT_EQ(back.id[i], s.id[i]);
    EXPECT_EQ(back.x[i], s.x[i]);
    EXPECT_EQ(back.radius[i], s.radius[i]);
  }
}

// Cost of clumps: a settled pack of about 2000 clumps of 1, 2, 4 and 8 spheres (and loose
// spheres for reference), timed over 500 steps. Prints; asserts nothing.
TEST(Benchmark, DISABLED_SettledClumpPacks) {
  const double r = 0.5e-3, a = 0.35 * r;
  const std::vector<std::vector<Vec3>> layouts = {
      {Vec3::Zero()},
      {Vec3(-0.5 * r, 0, 0), Vec3(0.5 * r, 0, 0)},
      {Vec3(a, a, a), Vec3(a, -a, -a), Vec3(-a, a, -a), Vec3(-a, -a, a)},
      {Vec3(a, a, a), Vec3(a, a, -a), Vec3(a, -a, a), Vec3(a, -a, -a), Vec3(-a, a, a), Vec3(-a, a, -a),
       Vec3(-a, -a, a), Vec3(-a, -a, -a)}};
  const std::size_t count = 2000;
  const double half_width = 15e-3;
  std::printf("kind,members,bodies,spheres,dt_s,settle_steps,ms_per_step,body_steps_per_s,sphere_steps_per_s,"
              "integration_ms,sums_ms,pair_ms,wall_ms,neighbour_ms\n");
  for (int kind = -1; kind < int(layouts.size()); ++kind) {
    const geometry::ClumpTemplate t = template_of(kind < 0 ? layouts[0] : layouts[std::size_t(kind)], r);
    const double bounding = dem::bounding_radius(t);
    // Bounding spheres at about a quarter of the box.
    const double height = double(count) * 4.0 / 3.0 * std::numbers::pi * std::pow(bounding, 3) / 0.25 /
                          (4 * half_width * half_width);
    dem::State s;
    dem::InsertRegion region;
    region.box = {Vec3(-half_width, -half_width, 0), Vec3(half_width, half_width, height)};
    if (kind < 0) {
      dem::InsertRequest req;
      req.count = count;
      req.radius = r;
      req.max_solid_fraction = 1;
      dem::insert_spheres(s, region, req);
    } else {
      dem::insert_clumps(s, region, t, 1.0, count, 0, 2500, 11);
    }
    dem::ModelSpec spec = box_spec(half_width, height);
    spec.materials[0].youngs_modulus = 1e7;
    spec.materials[0].restitution = 0.3;
    const dem::Model model = dem::compile_model(spec, s, "bench");
    dem::initialize(model, s);
    // Settled: until the grains' kinetic energy is a thousandth of their potential drop's.
    const double drop = dem::potential_energy(model, s);
    int settle = 0;
    for (; settle < 15000; ++settle) {
      dem::step(model, s);
      if (settle > 2000 && settle % 500 == 0 && dem::kinetic_energy(s) < 1e-3 * (drop - dem::potential_energy(model, s)))
        break;
    }
    const int steps = 500;
    const auto start = std::chrono::steady_clock::now();
    dem::StageTimes times;
    for (int n = 0; n < steps; ++n) dem::step(model, s, &times);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double bodies = kind < 0 ? double(s.size()) : double(s.bodies.size());
    std::printf("%s,%zu,%.0f,%zu,%.3g,%d,%.3f,%.4g,%.4g,%.4f,%.4f,%.4f,%.4f,%.4f\n", kind < 0 ? "spheres" : "clumps",
                t.spheres.size(), bodies, s.size(), model.dt, settle, 1e3 * seconds / steps, bodies * steps / seconds,
                double(s.size()) * steps / seconds, 1e3 * times.integration / steps, 1e3 * times.sums / steps,
                1e3 * times.pair_forces / steps, 1e3 * times.wall_forces / steps, 1e3 * times.neighbours / steps);
  }
}
