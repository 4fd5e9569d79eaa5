#pragma once
// `diefill bench mpi-bed` (mpi_bed.cpp): a bed of millions of grains split over MPI ranks.
#include <memory>
#include <nlohmann/json.hpp>

#include "bench/cases.hpp"

namespace bench {

// Collective over `ranks` (null: refused, the case needs mpirun); the result is complete on rank 0.
nlohmann::json run_mpi_bed(const Request& request, const std::shared_ptr<dem::Exchange>& ranks);

}  // namespace bench
