#include "dem/forces.hpp"

#include "dem/walls.hpp"

namespace dem {

namespace {

// Rows in parallel: the owner i sums its own share (gravity first, then its pairs in order)
// straight into f[i]; the partner's share goes to the pair buffer. Every pass over the grains
// splits them statically, alike: each thread meets the same grains in every stage, which stay
// in its core's cache (dynamic chunks moved them between cores: 17 % slower on two threads). Flattened: the law's slots
// inline into the loop (GCC otherwise calls the tangential slot, spilling the contact's
// kinematics to memory for every contact: 12 % slower).
template <class Law>
[[gnu::flatten]] void pair_forces(const Model& model, State& s) {
  NeighbourList& nl = s.neighbours;
  PairForces& pf = s.pair_forces;
  const std::size_t n = s.size();
  const double dt = model.dt;
  double max_overlap = 0;
  std::int64_t contacts = 0;
#pragma omp parallel for schedule(static) reduction(max : max_overlap) reduction(+ : contacts)
  for (std::size_t i = 0; i < n; ++i) {
    const std::int32_t first = nl.row_start[i], last = nl.row_start[i + 1];
    if (!s.active[i]) {
      s.f[i].setZero();
      s.torque[i].setZero();
      continue;  // an inactive grain has no listed pairs
    }
    const Vec3 xi = s.x[i], vi = s.v[i], wi = s.w[i];
    const double ri = s.radius[i], mi = s.mass[i];
    const int mat_i = s.material[i];
    // A clump's weight acts at its centre of mass, which its members' centres need not share.
    Vec3 fi = s.body[i] < 0 ? Vec3(mi * model.gravity) : Vec3::Zero(), ti = Vec3::Zero();
    for (std::int32_t p = first; p < last; ++p) {
      const std::size_t j = std::size_t(nl.partner[std::size_t(p)]);
      const Vec3 d = xi - s.x[j];
      const double reach = ri + s.radius[j];
      const double dist2 = d.squaredNorm();
      // Lists hold active grains only: grains are lost at rebuilds, which rebuild the lists.
      if (dist2 >= reach * reach) {
        // A contact that just ended clears its history and its share; most listed pairs were
        // apart already and cost only this flag.
        if (nl.touching[std::size_t(p)]) {
          nl.touching[std::size_t(p)] = 0;
          nl.history[std::size_t(p)] = ContactHistory{};
          pf.force[std::size_t(p)].setZero();
          pf.torque[std::size_t(p)].setZero();
        }
        continue;
      }
      nl.touching[std::size_t(p)] = 1;
      ContactHistory& h = nl.history[std::size_t(p)];
      const double dist = std::sqrt(dist2);
      const double rj = s.radius[j], mj = s.mass[j];
      // One division for three quotients: 1/dist, R* = ri rj / reach and m* = mi mj / (mi + mj).
      const double inverse = 1.0 / (dist * reach * (mi + mj));
      ContactKinematics c;
      c.n = d * (inverse * reach * (mi + mj));
      c.overlap = reach - dist;
      c.r_eff = ri * rj * (inverse * dist * (mi + mj));
      c.m_eff = mi * mj * (inverse * dist * reach);
      const double arm_i = ri - 0.5 * c.overlap, arm_j = rj - 0.5 * c.overlap;
      c.v_rel = vi - wi.cross(arm_i * c.n) - (s.v[j] + s.w[j].cross(arm_j * c.n));
      c.w_rel = wi - s.w[j];
      const ContactForce cf = Law::eval(model.params(mat_i, s.material[j]), c, dt, h);
      // Contact point at -arm_i n from i and +arm_j n from j: torques -arm n x F on both.
      const Vec3 moment = c.n.cross(cf.force);
      fi += cf.force;
      ti += -arm_i * moment + cf.rolling_torque;
      pf.force[std::size_t(p)] = -cf.force;
      pf.torque[std::size_t(p)] = -arm_j * moment - cf.rolling_torque;
      // Divide only when the overlap may be a new maximum.
      if (c.overlap > max_overlap * std::min(ri, rj)) max_overlap = c.overlap / std::min(ri, rj);
      ++contacts;
    }
    s.f[i] = fi;
    s.torque[i] = ti;
  }
  s.counters.max_overlap_rel = max_overlap;
  s.counters.contacts = contacts;
}

template <class Law>
[[gnu::flatten]] void wall_forces(const Model& model, State& s) {
  const std::vector<std::int32_t>& near = s.neighbours.near_wall;
  const double dt = model.dt;
  double max_overlap = s.counters.max_overlap_rel;
  std::int64_t contacts = 0;
  std::vector<double>& power = s.scratch_wall_power;
  power.assign(near.size(), 0.0);
  const std::size_t walls = model.meshes.size();
  if (s.wall_candidates.size() != near.size() * walls) s.wall_candidates.assign(near.size() * walls, WallCandidates{});
#pragma omp parallel for schedule(static) reduction(max : max_overlap) reduction(+ : contacts)
  for (std::size_t q = 0; q < near.size(); ++q) {
    const std::size_t i = std::size_t(near[q]);
    if (!s.active[i]) continue;
    WallHit hits[wall_slots_per_particle];
    const int count = wall_hits(model, s.time, s.x[i], s.radius[i], hits, wall_slots_per_particle,
                                walls ? &s.wall_candidates[q * walls] : nullptr);
    WallSlot* slots = &s.wall_slots[i * wall_slots_per_particle];
    WallSlot next[wall_slots_per_particle];
    bool taken[wall_slots_per_particle] = {};
    for (int k = 0; k < count; ++k) {
      const WallHit& hit = hits[k];
      // Recognise last step's contact with the same wall by its normal (a grain rolling over
      // a tessellated face changes triangles, not contacts).
      int match = -1;
      double best = 0.7;
      for (int o = 0; o < wall_slots_per_particle; ++o)
        if (!taken[o] && slots[o].wall == hit.wall && slots[o].normal.dot(hit.normal) > best)
          best = slots[o].normal.dot(hit.normal), match = o;
      next[k].wall = hit.wall;
      next[k].normal = hit.normal;
      if (match >= 0) {
        taken[match] = true;
        next[k].history = slots[match].history;
      }
      ContactKinematics c;
      c.n = hit.normal;
      c.overlap = s.radius[i] - hit.distance;
      c.r_eff = s.radius[i];
      c.m_eff = s.mass[i];
      const double arm = std::max(0.0, hit.distance);
      c.v_rel = s.v[i] - s.w[i].cross(arm * c.n) - hit.wall_velocity;
      c.w_rel = s.w[i] - hit.wall_angular_velocity;
      const int wall_material = hit.wall < std::int32_t(model.planes.size())
                                    ? model.planes[std::size_t(hit.wall)].material
                                    : model.meshes[std::size_t(hit.wall) - model.planes.size()].material;
      const ContactForce cf = Law::eval(model.params(s.material[i], wall_material), c, dt, next[k].history);
      s.f[i] += cf.force;
      s.torque[i] += -arm * c.n.cross(cf.force) + cf.rolling_torque;
      power[q] += cf.force.dot(hit.wall_velocity);
      if (c.overlap > max_overlap * s.radius[i]) max_overlap = c.overlap / s.radius[i];
      ++contacts;
    }
    for (int k = 0; k < wall_slots_per_particle; ++k)
      if (k < count) slots[k] = next[k];
      else if (slots[k].wall >= 0) slots[k] = WallSlot{};
  }
  double total_power = 0;
  for (double p : power) total_power += p;  // serial: the same sum for any thread count
  s.counters.wall_power = total_power;
  s.counters.max_overlap_rel = max_overlap;
  s.counters.wall_contacts = contacts;
}

// The laws in use, instantiated once each; the scene's names select one at run time.
template <template <class> class Stage>
void dispatch(const Model& m, State& s) {
  auto with_cohesion = [&](auto normal, auto tangential, auto rolling) {
    using N = decltype(normal);
    using T = decltype(tangential);
    using R = decltype(rolling);
    if (m.cohesion == CohesionLaw::sjkr) Stage<ContactLaw<N, T, R, SjkrCohesion>>::run(m, s);
    else Stage<ContactLaw<N, T, R, NoCohesion>>::run(m, s);
  };
  auto with_rolling = [&](auto normal, auto tangential) {
    switch (m.rolling) {
      case RollingLaw::epsd: return with_cohesion(normal, tangential, EpsdRolling{});
      case RollingLaw::cdt: return with_cohesion(normal, tangential, CdtRolling{});
      case RollingLaw::none: return with_cohesion(normal, tangential, NoRolling{});
    }
  };
  auto with_tangential = [&](auto normal) {
    if (m.tangential == TangentialLaw::mindlin) with_rolling(normal, MindlinTangential{});
    else with_rolling(normal, NoTangential{});
  };
  if (m.normal == NormalLaw::hertz) with_tangential(HertzNormal{});
  else with_tangential(LinearNormal{});
}

template <class Law>
struct PairStage {
  static void run(const Model& m, State& s) { pair_forces<Law>(m, s); }
};
template <class Law>
struct WallStage {
  static void run(const Model& m, State& s) { wall_forces<Law>(m, s); }
};

}  // namespace

void compute_pair_forces(const Model& model, State& state) { dispatch<PairStage>(model, state); }
void compute_wall_forces(const Model& model, State& state) { dispatch<WallStage>(model, state); }

void sum_forces(State& s, double kick_dt) {
  const NeighbourList& nl = s.neighbours;
  const PairForces& pf = s.pair_forces;
  const std::size_t n = s.size();
#pragma omp parallel for schedule(static)
  for (std::size_t j = 0; j < n; ++j) {
    if (!s.active[j]) continue;
    Vec3 f = s.f[j], t = s.torque[j];
    for (std::int32_t r = nl.reverse_start[j]; r < nl.reverse_start[j + 1]; ++r) {
      const std::size_t p = std::size_t(nl.reverse_pair[std::size_t(r)]);
      f += pf.force[p];
      t += pf.torque[p];
    }
    s.f[j] = f;
    s.torque[j] = t;
    // Clump members move with their bodies, kicked once their members' forces are summed.
    if (kick_dt > 0 && s.body[j] < 0) {
      s.v[j] += (kick_dt / s.mass[j]) * f;
      s.w[j] += (kick_dt / s.inertia[j]) * t;
    }
  }
}

double elastic_energy(const Model& model, const State& s) {
  // Hertz: U = (8/15) E* sqrt(R*) δ^{5/2}; linear: U = k δ² / 2.
  auto energy = [&](const PairParams& p, double r_eff, double overlap) {
    if (model.normal == NormalLaw::linear) return 0.5 * p.k_linear * overlap * overlap;
    return (8.0 / 15.0) * p.e_star * std::sqrt(r_eff) * overlap * overlap * std::sqrt(overlap);
  };
  double total = 0;
  const NeighbourList& nl = s.neighbours;
  for (std::size_t i = 0; i + 1 < nl.row_start.size(); ++i)
    for (std::int32_t p = nl.row_start[i]; p < nl.row_start[i + 1]; ++p) {
      const std::size_t j = std::size_t(nl.partner[std::size_t(p)]);
      const double reach = s.radius[i] + s.radius[j];
      const double overlap = reach - (s.x[i] - s.x[j]).norm();
      if (overlap > 0 && s.active[i] && s.active[j])
        total += energy(model.params(s.material[i], s.material[j]), s.radius[i] * s.radius[j] / reach, overlap);
    }
  for (std::int32_t i : nl.near_wall) {
    WallHit hits[wall_slots_per_particle];
    const int count = wall_hits(model, s.time, s.x[std::size_t(i)], s.radius[std::size_t(i)], hits, wall_slots_per_particle);
    for (int k = 0; k < count; ++k) {
      const int wm = hits[k].wall < std::int32_t(model.planes.size())
                         ? model.planes[std::size_t(hits[k].wall)].material
                         : model.meshes[std::size_t(hits[k].wall) - model.planes.size()].material;
      total += energy(model.params(s.material[std::size_t(i)], wm), s.radius[std::size_t(i)],
                      s.radius[std::size_t(i)] - hits[k].distance);
    }
  }
  return total;
}

}  // namespace dem
