#pragma once
// The DEM split over the ranks of MPI_COMM_WORLD (exchange.hpp; docs/ARCHITECTURE.md, "Domain
// decomposition"). Built when OpenMPI is present (DIEFILL_HAVE_MPI); the plain executable runs
// without mpirun as before.
#include <memory>

#include "dem/exchange.hpp"

namespace dem {

// For State::exchange: subdomains by recursive coordinate bisection of the grains, weighted by
// their listed pairs. Every rank calls it, after MPI_Init.
std::shared_ptr<Exchange> make_mpi_exchange();

}  // namespace dem
