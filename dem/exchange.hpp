#pragma once
// A run split over MPI ranks (docs/ARCHITECTURE.md, "Domain decomposition"): each rank owns the
// grains in its subdomain and holds, after them, ghost copies of the other ranks' grains within
// reach of it. This is what the step asks of the other ranks; a run on one process has no
// exchange (State::exchange is null) and makes no call. The MPI implementation
// (dem/mpi_exchange.cpp) is a library of its own, so that the DEM itself links no MPI.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <type_traits>
#include <vector>

#include "dem/types.hpp"

namespace dem {

struct Model;
struct State;

// A pair's contact history as one grain sees it, keyed by global ids, carried to a grain's new
// rank when it migrates.
struct CarriedPair {
  std::int64_t id, partner;
  Vec3f tangential, rolling;
};

// A grain as it travels between ranks (a ghost's copy, or a grain gathered for the outputs).
struct GrainRecord {
  std::int64_t id;
  Vec3 x, v, w;
  double radius, mass;
  std::int32_t material;
  std::uint8_t active;
  std::uint8_t unused[3];  // the padding, named: copies (a sort's too) keep it zero, and a file the same
};

// Byte buffers of plain records. The records hold numbers and Eigen's fixed-size vectors, which
// are arrays of doubles: copied as bytes, whatever Eigen declares.
template <typename T>
void put(std::vector<char>& buffer, const T& value) {
  static_assert(std::is_standard_layout_v<T>);
  const char* bytes = reinterpret_cast<const char*>(&value);
  buffer.insert(buffer.end(), bytes, bytes + sizeof(T));
}
template <typename T>
T take(const char*& at) {
  T value;
  std::memcpy(static_cast<void*>(&value), at, sizeof(T));
  at += sizeof(T);
  return value;
}

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
  // Every rank's `local` values, rank after rank, on every rank.
  virtual std::vector<double> all_gather(const std::vector<double>& local) = 0;
  // The step's one collective (dem/step.cpp): every rank's `local` values, rank after rank, on
  // every rank. The exchange sends its own beside them (the work its grains carry, weighed at the
  // last build), so that the neighbour rebuild the values may call for makes no collective of its
  // own unless it cuts the subdomains anew.
  virtual std::vector<double> agree(const State& state, const std::vector<double>& local) = 0;
  // Runs `work` on one rank after another in rank order (rank r starts when r - 1 is done), for an
  // output that every rank appends its own part to. Point to point: no collective.
  virtual void in_turn(const std::function<void()>& work) = 0;
  // The collective calls over every rank made so far (MPI_COMM_WORLD's reductions, gathers,
  // barriers, and an exchange with every rank), for the benchmarks.
  virtual std::int64_t global_collectives() const = 0;
  // How often the subdomains were cut, the first time included (a cut adds collectives of its own).
  virtual std::int64_t cuts() const = 0;
  // The point-to-point messages this rank has sent so far, and their bytes.
  virtual std::int64_t messages_sent() const = 0;
  virtual std::int64_t bytes_sent() const = 0;
  // Every rank's bytes, concatenated in rank order, on rank 0 (empty elsewhere).
  virtual std::vector<char> gather(const std::vector<char>& local) = 0;
  virtual void barrier() = 0;
  // At a neighbour rebuild: owned grains move to the rank whose subdomain holds them (a clump's
  // members all go where its body's centre lies; cut anew
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
  // What the exchange knows between two rebuilds (its subdomains, whom it sends which ghosts), for
  // a checkpoint resumed on the same rank count (dem/checkpoint.cpp): put, then restored as it was.
  virtual std::vector<char> saved() const = 0;
  virtual void restore(const char* bytes, std::size_t size) = 0;
};

}  // namespace dem
