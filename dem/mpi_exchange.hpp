#pragma once
// The DEM split over the ranks of MPI_COMM_WORLD (exchange.hpp; docs/ARCHITECTURE.md, "Domain
// decomposition"). Built when OpenMPI is present (DIEFILL_HAVE_MPI); the plain executable runs
// without mpirun as before.
#include <cstddef>
#include <memory>

#include "dem/exchange.hpp"

namespace dem {

// For State::exchange: subdomains by recursive coordinate bisection of the grains, weighted by
// their listed pairs. Every rank calls it, after MPI_Init, with the same largest_message: the most
// bytes one MPI message carries (MPI counts in int: at most INT_MAX). A longer buffer (a gathered
// state, a migration) travels in pieces; tests pass a few hundred bytes, so that a small scene
// takes the path of a large one.
std::shared_ptr<Exchange> make_mpi_exchange(std::size_t largest_message = std::size_t(1) << 30);

}  // namespace dem
