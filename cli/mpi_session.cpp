#include "cli/mpi_session.hpp"

#include <cstdlib>

#include "core/log.hpp"

#ifdef DIEFILL_HAVE_MPI
#include <mpi.h>

#include "dem/mpi_exchange.hpp"
#endif

namespace cli {

namespace {
std::shared_ptr<dem::Exchange> session_exchange;
}

#ifdef DIEFILL_HAVE_MPI
namespace {
// OpenMPI's mpirun sets OMPI_COMM_WORLD_SIZE in every rank's environment; a direct launch by a
// scheduler (srun) sets PMIx's or PMI's rank.
bool launched_by_mpi() { return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMIX_RANK") || std::getenv("PMI_RANK"); }
}  // namespace

MpiSession::MpiSession(int& argc, char**& argv) {
  if (!launched_by_mpi()) return;
  // OpenMP threads compute between the exchanges, which the main thread alone makes: FUNNELED is
  // what the standard asks of such a program (MPI_Init promises only SINGLE).
  int provided = MPI_THREAD_SINGLE;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  session_exchange = dem::make_mpi_exchange();
  // One progress line, one set of warnings and one result: rank 0's (a warning comes from values
  // every rank shares). Errors still come from every rank.
  if (session_exchange->rank() != 0) diefill::log::set_level(diefill::log::Level::quiet);
  if (provided < MPI_THREAD_FUNNELED)
    diefill::log::warn("this MPI library gives no thread support (MPI_THREAD_FUNNELED); run one OpenMP thread per rank "
                       "(OMP_NUM_THREADS=1)");
}
MpiSession::~MpiSession() {
  if (!session_exchange) return;
  session_exchange.reset();
  MPI_Finalize();
}
void abort_all_ranks(int status) {
  MPI_Abort(MPI_COMM_WORLD, status);
  std::exit(status);  // MPI_Abort does not return; the compiler cannot know
}
#else
MpiSession::MpiSession(int&, char**&) {
  if (std::getenv("OMPI_COMM_WORLD_SIZE"))
    diefill::log::warn("launched by mpirun, but this diefill was built without OpenMPI: every rank runs the whole job "
                       "(install libopenmpi-dev and rebuild)");
}
MpiSession::~MpiSession() = default;
void abort_all_ranks(int status) { std::exit(status); }
#endif

std::shared_ptr<dem::Exchange> mpi_exchange() { return session_exchange; }

}  // namespace cli
