#pragma once
// Checkpoints: the whole State (particles, neighbour list with contact history, wall slots,
// counters) plus the hash of the Model that made it. A run resumed from one continues
// bit-for-bit like the uninterrupted run.
//
// Split over MPI ranks (exchange.hpp), a checkpoint holds the grains in id order with their
// contact histories keyed by global ids, gathered on rank 0 and written by it: any number of
// ranks can resume it (each takes its share; the first step builds the lists anew), with the same
// statistics, not the same bits, as the run that wrote it.
#include <filesystem>
#include <memory>

#include "dem/model.hpp"
#include "dem/state.hpp"

namespace dem {

// Collective when the state is split.
void write_checkpoint(const Model& model, const State& state, const std::filesystem::path& path);
// Throws InputError when the file is unreadable or was written by a different model. With an
// exchange (every rank reads the file), this rank's share, ready to step; without, the whole
// state of a single-process checkpoint.
State read_checkpoint(const Model& model, const std::filesystem::path& path, std::shared_ptr<Exchange> exchange = nullptr);

}  // namespace dem
