#pragma once
// Neighbour search: a cell grid over the domain builds a Verlet half list with a skin, rebuilt
// once the largest displacement since the last build (particles relative to each other, or to a
// moving wall; measured from the positions at the build as kept, plus their rounding) may exceed
// half the skin. Contact history survives rebuilds.
// Particles are re-sorted along the cells at every rebuild, for memory locality. O(N).
#include "dem/model.hpp"
#include "dem/state.hpp"

namespace dem {

// `largest_shift2`: the largest squared displacement of a grain since the last build [m²].
bool needs_rebuild(const Model& model, const State& state, double largest_shift2);
// Marks this rank's grains outside the domain as lost: counted, frozen, never silently dropped
// (a clump whole, when its centre leaves).
void lose_outside_domain(const Model& model, State& state);
// Loses the grains outside the domain, re-sorts, rebuilds the list, carries history.
void rebuild_neighbours(const Model& model, State& state);

}  // namespace dem
