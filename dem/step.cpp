#include "dem/step.hpp"

#include <fmt/core.h>

#include <cmath>
#include <limits>
#include <vector>

#include "core/sha256.hpp"
#include "core/timer.hpp"
#include "dem/bodies.hpp"
#include "dem/forces.hpp"
#include "dem/neighbours.hpp"
#include "dem/walls.hpp"

namespace dem {

namespace {

// The grains sorted anew: those outside the domain lost first, so that split over ranks none is
// sent to another rank as a ghost (or moved there) and then lost by its owner, which left the
// others touching a grain that no longer exists (two ranks stopped at t = 0 on an overlap of a
// grain lost on one rank: `diefill bench ring-10k` under mpirun); then the grains moved to the
// ranks whose subdomains hold them, with their ghosts, and the neighbour list rebuilt.
void regrid(const Model& model, State& s) {
  if (s.exchange) {
    lose_outside_domain(model, s);
    s.exchange->redistribute(model, s);
  }
  rebuild_neighbours(model, s);
}

// The first half of velocity Verlet in one pass: free grains kicked by half a step and moved a
// step (clump members were placed by their bodies already), and the largest displacement of this
// rank's grains since the neighbour list was built, which decides (over all ranks) whether to
// rebuild it.
double kick_and_drift(State& s, double half_dt, double dt) {
  kick_bodies(s, half_dt);
  drift_bodies(s, dt);
  const std::size_t n = s.owned();
  const Array<Vec3f>& built = s.neighbours.x_at_build;
  const bool listed = built.size() == s.size();
  // No list (a state read back or shared anew): every rank rebuilds, one holding no grain too.
  double largest = listed ? 0 : std::numeric_limits<double>::infinity();
#pragma omp parallel for schedule(static) reduction(max : largest)
  for (std::size_t i = 0; i < n; ++i) {
    if (!s.active[i]) continue;
    if (s.body[i] < 0) {
      s.v[i] += (half_dt / s.mass[i]) * s.f[i];
      s.w[i] += (half_dt / sphere_inertia(s.mass[i], s.radius[i])) * s.torque[i];
      s.x[i] += dt * s.v[i];
    }
    if (listed) largest = std::max(largest, (s.x[i] - built[i].cast<double>()).squaredNorm());
  }
  return largest;
}

// Forces on every grain; with kick_dt > 0 the second half kick of velocity Verlet follows in
// the same passes. Walls come before the partners' shares so that the last pass over the grains
// completes each force and kicks with it.
void forces(const Model& model, State& s, StageTimes* times, double kick_dt) {
  diefill::Stopwatch clock;
  compute_pair_forces(model, s);
  if (times) times->pair_forces += clock.seconds(), clock.restart();
  compute_wall_forces(model, s);
  if (times) times->wall_forces += clock.seconds(), clock.restart();
  sum_forces(s, kick_dt);
  sum_body_forces(model, s);
  if (kick_dt > 0) kick_bodies(s, kick_dt);
  if (times) times->sums += clock.seconds();
}

// Which contact overlaps most, for the stop message: a serial scan, run once when stopping.
std::string worst_overlap(const Model& model, const State& s) {
  double worst = -1;
  std::string where;
  const NeighbourList& nl = s.neighbours;
  for (std::size_t i = 0; i + 1 < nl.row_start.size(); ++i) {
    if (!s.active[i]) continue;
    for (std::int32_t p = nl.row_start[i]; p < nl.row_start[i + 1]; ++p) {
      const std::size_t j = std::size_t(nl.partner[std::size_t(p)]);
      const double rel = (s.radius[i] + s.radius[j] - (s.x[i] - s.x[j]).norm()) / std::min(s.radius[i], s.radius[j]);
      if (rel > worst)
        worst = rel, where = fmt::format("grains {} and {} at ({:.4g}, {:.4g}, {:.4g}) mm", s.id[i], s.id[j],
                                         1e3 * s.x[i].x(), 1e3 * s.x[i].y(), 1e3 * s.x[i].z());
    }
  }
  WallHit hits[wall_slots_per_particle];
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (!s.active[i]) continue;
    const int count = wall_hits(model, s.time, s.x[i], s.radius[i], hits, wall_slots_per_particle);
    for (int k = 0; k < count; ++k) {
      const double rel = (s.radius[i] - hits[k].distance) / s.radius[i];
      const std::size_t w = std::size_t(hits[k].wall);
      const std::string& wall = w < model.planes.size() ? model.planes[w].name : model.meshes[w - model.planes.size()].name;
      if (rel <= worst) continue;
      worst = rel, where = fmt::format("grain {} and the wall \"{}\" at ({:.4g}, {:.4g}, {:.4g}) mm", s.id[i], wall,
                                       1e3 * s.x[i].x(), 1e3 * s.x[i].y(), 1e3 * s.x[i].z());
      // Candidate triangles come from the voxels: coarser than the grain, they can miss a face.
      if (w >= model.planes.size())
        if (const double voxel = model.meshes[w - model.planes.size()].field->voxel; voxel > s.radius[i])
          where += fmt::format(" (its voxels, {:.3g} mm, are coarser than the grain's radius {:.3g} mm, so a face near the "
                               "grain can be missed: build the wall's field at a quarter of the grain radius)",
                               voxel * 1e3, s.radius[i] * 1e3);
    }
  }
  return where;
}

// Mechanical energy may only grow by what walls deliver; checked every `energy_interval` steps.
constexpr int energy_interval = 200;

// What the checks of a step need from every rank. A split run makes one collective per step
// (docs/ARCHITECTURE.md, "Domain decomposition"): after the drift, every rank sends these
// values of its own and receives everyone's (Exchange::agree). The rebuild test needs the drift's
// displacement at once; the checks of the state the step started from (the last step's overlaps,
// every `energy_interval` steps its energy) ride along, so that a failed check is reported one
// step after the step that failed it. A single process makes the same checks at the end of each
// step.
enum Signal : std::size_t { shift2, overlap, diverged, energy, wall_work, stop_asked, signal_count };

struct Agreed {
  double shift2 = 0, overlap = 0, diverged = -1, energy = 0, wall_work = 0;
  bool stop_asked = false;
};

// The signals of the state as it stands (the end of the last step), the displacement left at 0.
std::vector<double> local_signals(const Model& model, const State& s, bool energy_due) {
  std::vector<double> local(signal_count, 0.0);
  local[overlap] = s.counters.max_overlap_rel;
  local[diverged] = -1;
  if (energy_due) {
    for (std::size_t i = 0; i < s.owned() && local[diverged] < 0; ++i)
      if (s.active[i] && !(s.x[i].allFinite() && s.v[i].allFinite() && s.w[i].allFinite())) local[diverged] = double(s.id[i]);
    local[energy] = kinetic_energy(s) + potential_energy(model, s) + elastic_energy(model, s);
  }
  local[wall_work] = s.wall_work;
  local[stop_asked] = s.counters.stop_asked ? 1 : 0;
  return local;
}

// Largest values and sums in rank order over the ranks (the local ones on a single process).
Agreed agree(State& s, const std::vector<double>& local) {
  const std::vector<double> all = s.exchange ? s.exchange->agree(s, local) : local;
  Agreed g;
  for (std::size_t at = 0; at < all.size(); at += signal_count) {
    g.shift2 = std::max(g.shift2, all[at + shift2]), g.overlap = std::max(g.overlap, all[at + overlap]);
    g.diverged = std::max(g.diverged, all[at + diverged]);
    g.energy += all[at + energy], g.wall_work += all[at + wall_work];
    g.stop_asked = g.stop_asked || all[at + stop_asked] > 0;
  }
  return g;
}

// The checks of the state at `time`, from the agreed values.
StepReport check(const Model& model, State& s, const Agreed& g, bool energy_due, double time) {
  StepReport r;
  s.counters.checked_overlap_rel = g.overlap;
  s.counters.stop_agreed = g.stop_asked;
  if (g.overlap > model.stop_overlap) {
    r.status = StepStatus::overlap;
    r.message = fmt::format(
        "a contact overlap reached {:.3g} of the grain radius (limit {:.3g}) at t = {:.6g} s, between {}: "
        "the time step {:.3g} s is too large for the stiffness or the impact speed, or a moving wall "
        "pinches grains. Lower simulation.time_step (or its fraction), soften the material, or slow the walls",
        g.overlap, model.stop_overlap, time, worst_overlap(model, s), model.dt);
    return r;
  }
  if (!energy_due) return r;
  if (g.diverged >= 0) {
    r.status = StepStatus::non_finite;
    r.message = fmt::format("grain {} has a non-finite position or velocity at t = {:.6g} s: the "
                            "integration diverged. Lower simulation.time_step",
                            std::int64_t(g.diverged), time);
    return r;
  }
  if (s.energy_reference_set) {
    const double budget = s.energy_reference + g.wall_work;
    s.counters.energy_gain = (g.energy - budget) / std::max(s.energy_scale, 1e-300);
    const double slack = 1e-3 * std::abs(s.energy_reference) + 1e-3 * s.energy_scale + 1e-12;
    if (g.energy > budget + slack) {
      r.status = StepStatus::energy_growth;
      r.message = fmt::format(
          "the grains' energy grew to {:.4g} J, beyond the {:.4g} J gravity and the walls can "
          "have given them, at t = {:.6g} s: the time step {:.3g} s is unstable. Lower "
          "simulation.time_step",
          g.energy, budget, time, model.dt);
    }
  }
  return r;
}

// The energy is checked at the end of every energy_interval-th step.
bool energy_due(const State& s) { return s.step > 0 && s.step % energy_interval == 0; }

// The sum over the ranks (the local one on a single process), outside the stepping loop.
double global_sum(const State& s, double local) { return s.exchange ? s.exchange->sum(local) : local; }

}  // namespace

// Clump members carry their body's motion: their energy is the body's, counted once.
double kinetic_energy(const State& s) {
  double e = 0;
  for (std::size_t i = 0; i < s.owned(); ++i)
    if (s.active[i] && s.body[i] < 0) e += 0.5 * s.mass[i] * s.v[i].squaredNorm() + 0.5 * sphere_inertia(s.mass[i], s.radius[i]) * s.w[i].squaredNorm();
  return e + body_kinetic_energy(s);
}

double potential_energy(const Model& model, const State& s) {
  double e = 0;
  for (std::size_t i = 0; i < s.owned(); ++i)
    if (s.active[i] && s.body[i] < 0) e -= s.mass[i] * model.gravity.dot(s.x[i]);
  return e + body_potential_energy(model, s);
}

void initialize(const Model& model, State& s) {
  s.f.resize(s.size(), Vec3::Zero());
  s.torque.resize(s.size(), Vec3::Zero());
  regrid(model, s);
  forces(model, s, nullptr, 0);
  s.energy_reference = global_sum(s, kinetic_energy(s) + potential_energy(model, s) + elastic_energy(model, s));
  s.energy_scale = 0;
  for (std::size_t i = 0; i < s.owned(); ++i)
    if (s.body[i] < 0) s.energy_scale += s.mass[i] * model.gravity.norm() * s.radius[i];
  for (std::size_t b = 0; b < s.bodies.size(); ++b)
    for (std::int32_t k = s.bodies.member_start[b]; k < s.bodies.member_start[b + 1]; ++k)
      s.energy_scale += s.bodies.mass[b] * model.gravity.norm() * s.radius[std::size_t(s.bodies.member[std::size_t(k)])] /
                        double(s.bodies.member_start[b + 1] - s.bodies.member_start[b]);
  s.energy_scale = global_sum(s, s.energy_scale);
  s.energy_reference_set = true;
}

StepReport step(const Model& model, State& s, StageTimes* times) {
  diefill::Stopwatch clock;
  // Split, the checks of the state this step starts from ride in its one collective; a single
  // process checks each step's own state at its end, as soon as it is known (a grain driven into a
  // thin wall stops the run before the next step can push it through: test_dem_walls.cpp).
  const bool split = s.exchange != nullptr, due = split && energy_due(s);
  const double checked_time = s.time;
  std::vector<double> local = split ? local_signals(model, s, due) : std::vector<double>(signal_count, 0.0);
  local[shift2] = kick_and_drift(s, 0.5 * model.dt, model.dt);
  s.time += model.dt;
  ++s.step;
  const Agreed agreed = agree(s, local);
  if (times) times->integration += clock.seconds(), clock.restart();
  if (needs_rebuild(model, s, agreed.shift2)) {
    regrid(model, s);
  } else if (s.exchange) {
    s.exchange->update_ghosts(s);
  }
  if (times) times->neighbours += clock.seconds(), clock.restart();
  forces(model, s, times, 0.5 * model.dt);
  clock.restart();
  s.wall_work += s.counters.wall_power * model.dt;  // this rank's; summed over the ranks when checked
  StepReport report = split ? check(model, s, agreed, due, checked_time) : check_last_step(model, s);
  if (times) times->monitor += clock.seconds();
  return report;
}

StepReport check_last_step(const Model& model, State& s) {
  const bool due = energy_due(s);
  return check(model, s, agree(s, local_signals(model, s, due)), due, s.time);
}

std::string state_hash(const State& s) {
  diefill::Sha256 h;
  auto put = [&h](const auto& v) { h.update(v.data(), v.size() * sizeof(v[0])); };
  put(s.id);
  put(s.x);
  put(s.v);
  put(s.w);
  put(s.active);
  put(s.neighbours.tangential);
  put(s.neighbours.rolling);
  // Bodies only where there are any, so that a sphere scene hashes as it always did.
  if (s.bodies.size() > 0) {
    put(s.body);
    put(s.bodies.x);
    put(s.bodies.v);
    put(s.bodies.q);
    put(s.bodies.l);
    put(s.bodies.active);
    put(s.bodies.member);
  }
  for (const WallSlot& w : s.wall_slots) {
    h.update(&w.wall, sizeof w.wall);
    h.update(w.history.tangential.data(), sizeof(double) * 3);
    h.update(w.history.rolling.data(), sizeof(double) * 3);
  }
  h.update(&s.time, sizeof s.time);
  h.update(&s.step, sizeof s.step);
  return h.hex();
}

}  // namespace dem
