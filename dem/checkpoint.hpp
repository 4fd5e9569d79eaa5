#pragma once
// Checkpoints: the whole State (particles, neighbour list with contact history, wall slots,
// counters) plus the hash of the Model that made it. A run resumed from one continues
// bit-for-bit like the uninterrupted run.
//
// Split over MPI ranks (exchange.hpp), every rank writes its own piece beside the file
// (PATH.rank-R-of-N: its grains, ghosts, lists and histories, and what its exchange knows) and
// rank 0 the file itself, an index: no rank holds another's grains. The same rank count resumes
// it bit for bit; any other count too (each rank takes every N-th piece's own grains, with their
// histories keyed by global ids; the first step builds the lists and subdomains anew), with the
// same statistics, not the same bits.
#include <filesystem>
#include <memory>
#include <string>

#include "dem/model.hpp"
#include "dem/state.hpp"

namespace dem {

// Collective when the state is split.
void write_checkpoint(const Model& model, const State& state, const std::filesystem::path& path);
// Throws InputError when the file is unreadable or was written by a different model. With an
// exchange (every rank reads the file), this rank's share, ready to step; without, the whole
// state of a single-process checkpoint.
State read_checkpoint(const Model& model, const std::filesystem::path& path, std::shared_ptr<Exchange> exchange = nullptr);

// The layout's name, written at the head of every single-process checkpoint: a cache of
// checkpoints keyed by it is written anew when the layout changes (bench/cases.cpp).
std::string checkpoint_layout();

// Removes a checkpoint and its pieces.
void remove_checkpoint(const std::filesystem::path& path);

}  // namespace dem
