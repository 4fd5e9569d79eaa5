#pragma once
// One time step, as a table of contents of its stages (each timed):
//   the last step's checks, kick (half) and drift -> the ranks agree (one collective) ->
//   neighbour update (when needed) -> grain-grain forces -> grain-wall forces -> sums with the
//   second half kick -> body sums and kick (clumps) -> the checks' verdict
// ("sums" times the last pass over the grains, kick included).
// Velocity Verlet: second order and symplectic for conservative forces; clumps rotate by the
// splitting in bodies.hpp.
#include <string>

#include "dem/model.hpp"
#include "dem/state.hpp"

namespace dem {

enum class StepStatus { ok, non_finite, overlap, energy_growth };

struct StageTimes {
  double neighbours = 0, pair_forces = 0, sums = 0, wall_forces = 0, integration = 0, monitor = 0;
};

struct StepReport {
  StepStatus status = StepStatus::ok;
  std::string message;  // cause and remedy when status is not ok
};

// Neighbour list and forces for the current positions; call once before stepping.
void initialize(const Model& model, State& state);
// Advances one step. Nothing throws inside the loop: a failed check returns its status. Split over
// ranks, a step checks the state it started from (the step before's overlaps, and its energy every
// few hundred steps) with the one collective it makes, so that a failure is reported one step
// late; a single process checks the step's own state.
StepReport step(const Model& model, State& state, StageTimes* times = nullptr);
// The checks of the last step taken, which the next step would make: for the end of a run.
// Collective when split.
StepReport check_last_step(const Model& model, State& state);

// Energy budget for the monitor [J].
double kinetic_energy(const State& state);
double potential_energy(const Model& model, const State& state);

// A hash of the state's bits (positions, velocities, spins, histories, bodies, time): identical
// states, and only those, hash the same.
std::string state_hash(const State& state);

}  // namespace dem
