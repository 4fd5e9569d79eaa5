#pragma once
// The performance cases of `diefill bench` (docs/PERFORMANCE.md, "The commands"): each times a
// scene on the thread counts asked and returns machine-readable results.
//   ring-10k, ring-100k   settled dense packs of monodisperse spheres in the ring die
//   liggghts              the LIGGGHTS reference scene (../shared/bench/liggghts): the same
//                         settled pack, container mesh, contact law and time step
//   scaling               tiles of the LIGGGHTS pack, 5k to 500k grains
//   run-ring              `diefill run dies/ring.stl` with the default scene, from nothing (no
//                         cached die or shoe): the user's wait, stage by stage
//   mpi-bed               under mpirun: a bed of millions of grains split over the ranks
#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "dem/exchange.hpp"

namespace bench {

struct Request {
  std::vector<std::string> cases;  // empty: ring-10k and ring-100k
  std::vector<int> threads;        // thread counts to time; empty: 1 and 2
  int steps = 2000;
  std::filesystem::path cache = "out/bench";  // prepared packs and SDFs
  std::filesystem::path pack;      // liggghts, scaling: the settled pack (LAMMPS dump)
  std::filesystem::path stl;       // liggghts: the container (mm)
  std::vector<std::size_t> sizes = {5000, 15000, 50000, 150000, 500000};  // scaling: grain counts
  // scaling: a bed of several tiles as laid out, not settled again (its seams move while it is
  // timed, so its rate is not like for like): for its bytes per grain and its rebuild's time
  // without the settling (over an hour for 500k grains).
  bool unsettled_beds = false;
  std::int64_t grains = 10'000'000;  // mpi-bed: the bed's grains
  std::int64_t checkpoint_at = 0;    // mpi-bed: the step at which a checkpoint is written (0: none)
  std::filesystem::path resume;      // mpi-bed: go on from this checkpoint
};

// The cases' results as one JSON document. Under mpirun every rank calls it with the session's
// exchange (null on one process); the result is complete on rank 0.
nlohmann::json run_cases(const Request& request, const std::shared_ptr<dem::Exchange>& ranks);

}  // namespace bench
