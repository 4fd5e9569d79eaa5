#pragma once
// One time step, as a table of contents of its stages (each timed):
//   kick (half) and drift -> neighbour update (when needed) -> grain-grain forces ->
//   grain-wall forces -> sums with the second half kick -> body sums and kick (clumps) -> monitor
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
// Advances one step. Nothing throws inside the loop: a failed check returns its status.
StepReport step(const Model& model, State& state, StageTimes* times = nullptr);

// Energy budget for the monitor [J].
double kinetic_energy(const State& state);
double potential_energy(const Model& model, const State& state);

// A hash of the state's bits (positions, velocities, spins, histories, bodies, time): identical
// states, and only those, hash the same.
std::string state_hash(const State& state);

}  // namespace dem
