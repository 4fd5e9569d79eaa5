#pragma once
// MPI for a run launched by mpirun (docs/ARCHITECTURE.md, "Domain decomposition"): initialised
// for the program's life when the launcher's environment says so and the build has OpenMPI;
// otherwise nothing, and diefill runs as one process.
#include <memory>

#include "dem/exchange.hpp"

namespace cli {

class MpiSession {
 public:
  MpiSession(int& argc, char**& argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
};

// The exchange of this run's ranks; null on one process without mpirun.
std::shared_ptr<dem::Exchange> mpi_exchange();

// Ends every rank of the run with `status` (an error on one rank that the others cannot know of).
[[noreturn]] void abort_all_ranks(int status);

}  // namespace cli
