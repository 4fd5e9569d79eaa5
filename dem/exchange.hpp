#pragma once
// A run split over MPI ranks (docs/ARCHITECTURE.md, "Domain decomposition"): each rank owns the
// grains in its subdomain and holds, after them, ghost copies of the other ranks' grains within
// reach of it. This is what the step asks of the other ranks; a run on one process has no
// exchange (State::exchange is null) and makes no call. The MPI implementation
// (dem/mpi_exchange.cpp) is a library of its own, so that the DEM itself links no MPI.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "dem/types.hpp"

namespace dem {

struct Model;
struct State;

// A pair's contact history as one grain sees it, keyed by global ids, carried to a grain's new
// rank when it migrates.
struct CarriedPair {
  std::int64_t id, partner;
  Vec3 tangential, rolling;
};

class Exchange {
 public:
  virtual ~Exchange() = default;
  virtual int rank() const = 0;
  virtual int ranks() const = 0;
  // The same on every rank; a sum adds the ranks' values in rank order, so that a rank count
  // gives the same bits every time.
  virtual double max(double local) = 0;
  virtual double sum(double local) = 0;
  virtual std::int64_t sum(std::int64_t local) = 0;
  // At a neighbour rebuild: owned grains move to the rank whose subdomain holds them (cut anew
  // when the heaviest rank carries more than 1.2 times the mean work), with their pair contact
  // histories (left in state.carried_pairs, keyed by global ids) and their wall contacts; then
  // every rank receives as ghosts the other ranks' grains within reach of its subdomain.
  virtual void redistribute(const Model& model, State& state) = 0;
  // The rebuild re-sorted the owned grains (new_index: old index -> new), which the ghosts sent
  // every step are listed by.
  virtual void reordered(const std::vector<std::int32_t>& new_index) = 0;
  // Every step without a rebuild: the ghosts' positions and velocities, from their owners.
  virtual void update_ghosts(State& state) = 0;
  // What this rank sends in one update_ghosts [bytes].
  virtual std::size_t ghost_bytes_per_step() const = 0;
};

}  // namespace dem
