#pragma once
// Force stage: gravity, grain-grain contacts (per-pair buffers summed per grain in a fixed
// order) and grain-wall contacts, with the contact law the model names.
#include "dem/model.hpp"
#include "dem/state.hpp"

namespace dem {

// Gravity and the pairs' forces on their row owners into f, torque; partners' shares buffered.
void compute_pair_forces(const Model& model, State& state);
// Adds the walls' forces of the grains near them.
void compute_wall_forces(const Model& model, State& state);
// Adds the buffered partner shares, in a fixed order, and with kick_dt > 0 kicks every free
// grain by its completed force in the same pass: v += kick_dt f / m, ω += kick_dt τ / I.
void sum_forces(State& state, double kick_dt);

// Elastic energy stored in the grain-grain and grain-wall overlaps [J] (normal springs).
double elastic_energy(const Model& model, const State& state);

}  // namespace dem
