#pragma once
// The whole run seen from one rank of a split (exchange.hpp; docs/ARCHITECTURE.md, "Domain
// decomposition"): a rank's share of a whole state, the whole state gathered on rank 0 for the
// outputs, and the contact histories that travel with grains, keyed by global ids. Every call
// that takes a split state is collective: every rank makes it, in the same order. On a single
// process (no exchange) each is the plain thing and makes no call.
#include <exception>
#include <functional>
#include <memory>
#include <vector>

#include "dem/state.hpp"

namespace dem {

GrainRecord grain_record(const State& state, std::size_t i);
void append_grain(State& state, const GrainRecord& grain);
// Keeps the grains listed in `keep`, in that order (their per-grain arrays only).
void keep_grains(State& state, const std::vector<std::size_t>& keep);

// Per owned grain, the histories of its pairs as it sees them: from the neighbour list (a pair of
// two owned grains listed for both), or, before the first list is built, from carried_pairs.
std::vector<std::vector<CarriedPair>> contact_histories(const State& state);

// Which of `count` grains every rank holds alike (read from one file, drawn from one seed) this
// rank takes: every ranks-th, from its rank on; they migrate to their subdomains at the first build.
std::vector<std::size_t> share_indices(std::size_t count, const Exchange& exchange);

// A rank's share of a state every rank holds whole (share_indices). No exchange: the whole state.
State share_of(State whole, std::shared_ptr<Exchange> exchange);

// Appends this rank's share of `fresh` (grains every rank drew alike) to a split state between
// two runs of the stepping loop: the ghosts are dropped and the lists' contact histories kept by
// id (carried_pairs) for the next initialize().
void add_share(State& state, const State& fresh);

// Rank 0 (or a single process) writes the outputs.
bool writes_outputs(const State& state);
// The owned grains of every rank in id order, on rank 0 (empty elsewhere), with the time, the
// step and the grains lost; no lists or contacts.
State gathered(const State& state);
// Calls `use` with the whole state where the outputs are written: the state itself on a single
// process, the gathered one on rank 0 of a split. A failure there (a full disk) ends the call on
// every rank: rank 0 rethrows it, the others throw InputError.
void with_whole_state(const State& state, const std::function<void(const State&)>& use);
// After a step some ranks may have failed in (writing a file, reading a cache): every rank learns
// it; the failed ones rethrow their error, the others throw InputError. Collective.
void agree_on_failure(Exchange& exchange, const std::exception_ptr& failure);

}  // namespace dem
