#pragma once
// `diefill bench mpi-bed` (bench_mpi.cpp): a bed of millions of grains split over MPI ranks.
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"

namespace cli {

// Collective; the result is complete on rank 0.
nlohmann::json run_mpi_bed(const BenchCommand& command);

}  // namespace cli
