// The pair stage's bookkeeping against a brute-force reference: grains sorted along a curve
// into blocks, partners' shares added directly within a block and buffered across blocks
// (docs/ARCHITECTURE.md, "Model and state"), contact history carried across re-sorting. A
// compressed lattice of a few thousand grains spans a dozen blocks, so that thousands of its
// contacts cross between blocks.
#include <gtest/gtest.h>

#include <map>
#include <utility>

#include "dem/forces.hpp"
#include "dem/neighbours.hpp"
#include "dem/insert.hpp"
#include "dem_support.hpp"

using dem::Vec3;

namespace {

using Law = dem::ContactLaw<dem::HertzNormal, dem::MindlinTangential, dem::EpsdRolling, dem::NoCohesion>;

// Touching pairs' history by grain ids, smaller id first and seen from it (the list stores the
// lower index's view, and sorting may swap which id has it).
using Histories = std::map<std::pair<std::int64_t, std::int64_t>, dem::ContactHistory>;

Histories histories_by_id(const dem::State& s) {
  Histories out;
  const dem::NeighbourList& nl = s.neighbours;
  for (std::size_t i = 0; i + 1 < nl.row_start.size(); ++i)
    for (std::int32_t p = nl.row_start[i]; p < nl.row_start[i + 1]; ++p) {
      if (!nl.touching[std::size_t(p)]) continue;
      const std::size_t j = std::size_t(nl.partner[std::size_t(p)]);
      const double sign = s.id[i] < s.id[j] ? 1.0 : -1.0;
      dem::ContactHistory h;
      h.tangential = sign * nl.tangential[std::size_t(p)].cast<double>();
      h.rolling = sign * nl.rolling[std::size_t(p)].cast<double>();
      out[{std::min(s.id[i], s.id[j]), std::max(s.id[i], s.id[j])}] = h;
    }
  return out;
}

// A simple cubic lattice 2 % tighter than the grains (every grain touches its six neighbours),
// radii within ±2 %, random velocities and spins; `materials` alternate along the ids.
dem::State compressed_lattice(int materials) {
  dem::State s;
  dem::Random random(17);
  const double r = 0.3e-3, spacing = 1.96 * r;
  std::int64_t id = 0;
  for (int a = 0; a < 15; ++a)
    for (int b = 0; b < 15; ++b)
      for (int c = 0; c < 14; ++c, ++id)
        s.add_sphere(id, spacing * Vec3(a, b, c), r * random.uniform(0.98, 1.02), 2500, int(id % materials),
                     0.05 * Vec3(random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1)),
                     300 * Vec3(random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1)));
  return s;
}

dem::Model lattice_model(const dem::State& s, int materials) {
  std::vector<dem::Material> m(std::size_t(materials), test::glass(0.5, 0.4));
  for (int k = 0; k < materials; ++k) m[std::size_t(k)].rolling_friction = 0.1 + 0.05 * k;
  for (int k = 0; k < materials; ++k) m[std::size_t(k)].name = "glass " + std::to_string(k);
  dem::ModelSpec spec = test::spec_with(m);
  spec.law.rolling = "epsd";
  spec.max_impact_speed = 0.5;
  return dem::compile_model(spec, s, "lattice");
}

// Forces and torques of every grain summed pair by pair over all pairs, from the given history.
std::pair<std::vector<Vec3>, std::vector<Vec3>> brute_force(const dem::Model& model, const dem::State& s, const Histories& before) {
  std::vector<Vec3> f(s.size(), Vec3::Zero()), t(s.size(), Vec3::Zero());
  for (std::size_t i = 0; i < s.size(); ++i)
    for (std::size_t j = i + 1; j < s.size(); ++j) {
      const Vec3 d = s.x[i] - s.x[j];
      const double reach = s.radius[i] + s.radius[j], dist = d.norm();
      if (dist >= reach) continue;
      dem::ContactKinematics c;
      c.n = d / dist;
      c.overlap = reach - dist;
      c.r_eff = s.radius[i] * s.radius[j] / reach;
      c.m_eff = s.mass[i] * s.mass[j] / (s.mass[i] + s.mass[j]);
      const double arm_i = s.radius[i] - 0.5 * c.overlap, arm_j = s.radius[j] - 0.5 * c.overlap;
      const Vec3 contact_velocity_i = s.v[i] + s.w[i].cross(-arm_i * c.n), contact_velocity_j = s.v[j] + s.w[j].cross(arm_j * c.n);
      c.v_rel = contact_velocity_i - contact_velocity_j;
      c.w_rel = s.w[i] - s.w[j];
      const std::pair key{std::min(s.id[i], s.id[j]), std::max(s.id[i], s.id[j])};
      const double sign = s.id[i] < s.id[j] ? 1.0 : -1.0;
      dem::ContactHistory h;
      if (const auto found = before.find(key); found != before.end())
        h.tangential = sign * found->second.tangential, h.rolling = sign * found->second.rolling;
      const dem::ContactForce cf = Law::eval(model.params(s.material[i], s.material[j]), c, model.dt, h);
      f[i] += cf.force;
      f[j] -= cf.force;
      t[i] += (-arm_i * c.n).cross(cf.force) + cf.rolling_torque;
      t[j] += (arm_j * c.n).cross(-cf.force) - cf.rolling_torque;
    }
  return {f, t};
}

void expect_assembly_matches_brute_force(int materials) {
  dem::State s = compressed_lattice(materials);
  const dem::Model model = lattice_model(s, materials);
  dem::initialize(model, s);
  for (int n = 0; n < 40; ++n) dem::step(model, s);  // histories build up
  ASSERT_GT(s.neighbours.blocks(), 10u);
  ASSERT_GT(s.neighbours.cross_reverse.size(), 1000u) << "contacts between blocks";

  // Re-sorting keeps every touching pair's history, bit for bit.
  const Histories before = histories_by_id(s);
  dem::rebuild_neighbours(model, s);
  const Histories after = histories_by_id(s);
  ASSERT_GT(before.size(), 5000u);  // of the lattice's 8,900 bonds
  std::size_t carried = 0;
  for (const auto& [key, h] : before) {
    const auto found = after.find(key);
    if (h.tangential.squaredNorm() + h.rolling.squaredNorm() == 0) continue;  // nothing to carry
    ASSERT_NE(found, after.end()) << key.first << "-" << key.second;
    EXPECT_EQ(found->second.tangential, h.tangential);
    EXPECT_EQ(found->second.rolling, h.rolling);
    ++carried;
  }
  EXPECT_GT(carried, 5000u);

  // Every grain's force and torque: the sum over its contacts, to rounding.
  const auto [f, t] = brute_force(model, s, after);
  dem::compute_pair_forces(model, s);
  dem::sum_forces(s, 0);
  double f_scale = 0, t_scale = 0;
  for (std::size_t i = 0; i < s.size(); ++i) f_scale = std::max(f_scale, f[i].norm()), t_scale = std::max(t_scale, t[i].norm());
  for (std::size_t i = 0; i < s.size(); ++i) {
    ASSERT_LT((s.f[i] - f[i]).norm(), 1e-12 * f_scale) << "grain " << s.id[i];
    ASSERT_LT((s.torque[i] - t[i]).norm(), 1e-12 * t_scale) << "grain " << s.id[i];
  }
}

}  // namespace

TEST(PairAssembly, OneMaterialSumsEveryContactAcrossBlocksAndKeepsHistory) { expect_assembly_matches_brute_force(1); }
TEST(PairAssembly, TwoMaterialsSumEveryContactAcrossBlocksAndKeepHistory) { expect_assembly_matches_brute_force(2); }
