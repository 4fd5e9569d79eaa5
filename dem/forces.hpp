#pragma once
// Force stage: gravity, grain-grain contacts (per-pair buffers summed per grain in a fixed
// order) and grain-wall contacts, with the contact law the model names.
#include "dem/model.hpp"
#include "dem/state.hpp"

namespace dem {

void compute_pair_forces(const Model& model, State& state);
void sum_forces(const Model& model, State& state);  // gravity + pair buffers into f, torque
void compute_wall_forces(const Model& model, State& state);

// Elastic energy stored in the grain-grain and grain-wall overlaps [J] (normal springs).
double elastic_energy(const Model& model, const State& state);

}  // namespace dem
