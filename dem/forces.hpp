#pragma once
// Force stage: gravity, grain-grain contacts (per-pair buffers summed per grain in a fixed
// order) and grain-wall contacts, with the contact law the model names.
#include "dem/model.hpp"
#include "dem/state.hpp"

namespace dem {

// Gravity and the pairs' forces on their row owners into f, torque; partners' shares buffered.
void compute_pair_forces(const Model& model, State& state);
// Adds the buffered partner shares, in a fixed order.
void sum_forces(const Model& model, State& state);
void compute_wall_forces(const Model& model, State& state);

// Elastic energy stored in the grain-grain and grain-wall overlaps [J] (normal springs).
double elastic_energy(const Model& model, const State& state);

}  // namespace dem
