#pragma once
// Checkpoints: the whole State (particles, neighbour list with contact history, wall slots,
// counters) plus the hash of the Model that made it. A run resumed from one continues
// bit-for-bit like the uninterrupted run.
#include <filesystem>

#include "dem/model.hpp"
#include "dem/state.hpp"

namespace dem {

void write_checkpoint(const Model& model, const State& state, const std::filesystem::path& path);
// Throws InputError when the file is unreadable or was written by a different model.
State read_checkpoint(const Model& model, const std::filesystem::path& path);

}  // namespace dem
