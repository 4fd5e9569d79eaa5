#pragma once
// Recursive coordinate bisection of weighted points spread over the ranks of MPI_COMM_WORLD: the
// subdomains of a split run (mpi_exchange.cpp; docs/ARCHITECTURE.md, "Domain decomposition"),
// and what bench/partition.cpp sets beside Zoltan's RCB.
#include <cstdint>
#include <limits>
#include <vector>

#include "dem/types.hpp"

namespace dem {

// A grain as the partitioner weighs it: itself and its listed pairs (a clump: at its body's
// centre, with its members' weights).
struct WeightedPoint {
  Vec3 x;
  std::int64_t weight;
};

struct Box {
  Vec3 lo = Vec3::Constant(-std::numeric_limits<double>::infinity()), hi = -lo;
  double distance(const Vec3& p) const { return (lo - p).cwiseMax(p - hi).cwiseMax(0.0).norm(); }
  double distance(const Box& other) const { return (lo - other.hi).cwiseMax(other.lo - hi).cwiseMax(0.0).norm(); }
};

class RcbPartition {
 public:
  // Cuts space so that each rank's box holds an equal share of the points' weight. Collective:
  // every rank passes its own points; every rank and every run finds the same cuts.
  void cut(const std::vector<WeightedPoint>& local);
  bool empty() const { return cuts_.empty(); }
  // The rank whose box holds x.
  int owner(const Vec3& x) const {
    int node = 0;
    while (cuts_[std::size_t(node)].axis >= 0) {
      const Cut& c = cuts_[std::size_t(node)];
      node = x[c.axis] < c.at ? c.below : c.above;
    }
    return cuts_[std::size_t(node)].rank;
  }
  // [ranks] they tile all of space.
  const std::vector<Box>& boxes() const { return boxes_; }
  // The collective calls cut() made so far (the benchmarks count every one).
  std::int64_t collectives() const { return collectives_; }
  // The cuts as bytes, field by field (no padding), and back: a checkpoint resumed on the same
  // rank count goes on with the cuts it had.
  void save(std::vector<char>& out) const;
  void restore(const char*& at);

 private:
  // A tree of cuts, each leaf a rank.
  struct Cut {
    int axis = -1;  // -1: a leaf
    double at = 0;
    int below = -1, above = -1, rank = -1;
  };
  std::vector<Cut> cuts_;
  std::vector<Box> boxes_;
  std::int64_t collectives_ = 0;
};

}  // namespace dem
