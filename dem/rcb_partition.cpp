#include "dem/rcb_partition.hpp"

#include "dem/exchange.hpp"

#include <mpi.h>

#include <algorithm>

namespace dem {

// Recursive coordinate bisection computed by all ranks together, level by level (as Zoltan's RCB
// does), each rank looking at its own grains only: a cut goes across the longest extent of its
// grains and is placed by bisecting the coordinate until the weight below it reaches the share of
// the ranks below it. Extents are reduced by minimum and weights as integers, so that every rank
// and every run finds the same cuts.
void RcbPartition::cut(const std::vector<WeightedPoint>& local) {
  int ranks = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  struct Node {
    int lo, hi, tree;  // ranks [lo, hi); its index in cuts_
    Box box;
  };
  cuts_.assign(1, Cut{});
  boxes_.assign(std::size_t(ranks), Box{});
  std::vector<Node> level;
  if (ranks > 1) level.push_back({0, ranks, 0, Box{}});
  else cuts_[0].rank = 0;
  std::vector<int> node_of(local.size(), ranks > 1 ? 0 : -1);  // the grain's node in `level`; -1: in a leaf
  constexpr int bisection_steps = 52;         // to the last bit of a double's mantissa
  while (!level.empty()) {
    const std::size_t m = level.size();
    // Per node: lows and negated highs of the grains (one minimum), and their total weight.
    std::vector<double> extent(6 * m, std::numeric_limits<double>::infinity());
    std::vector<std::int64_t> total(m, 0);
    for (std::size_t k = 0; k < local.size(); ++k) {
      if (node_of[k] < 0) continue;
      const std::size_t n = std::size_t(node_of[k]);
      for (int a = 0; a < 3; ++a)
        extent[6 * n + std::size_t(a)] = std::min(extent[6 * n + std::size_t(a)], local[k].x[a]),
        extent[6 * n + 3 + std::size_t(a)] = std::min(extent[6 * n + 3 + std::size_t(a)], -local[k].x[a]);
      total[n] += local[k].weight;
    }
    MPI_Allreduce(MPI_IN_PLACE, extent.data(), int(6 * m), MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
    MPI_Allreduce(MPI_IN_PLACE, total.data(), int(m), MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
    collectives_ += 2;
    std::vector<int> axis(m, 0);
    std::vector<double> low(m), high(m);  // the bisection's interval
    for (std::size_t n = 0; n < m; ++n) {
      const Vec3 lo(extent[6 * n], extent[6 * n + 1], extent[6 * n + 2]), hi(-extent[6 * n + 3], -extent[6 * n + 4], -extent[6 * n + 5]);
      if (total[n] > 0) (hi - lo).maxCoeff(&axis[n]);
      // No grains: any cut will do.
      low[n] = total[n] > 0 ? lo[axis[n]] : std::clamp(0.0, level[n].box.lo[0], level[n].box.hi[0]);
      high[n] = total[n] > 0 ? hi[axis[n]] : low[n];
    }
    std::vector<std::int64_t> below(m);
    for (int step = 0; step < bisection_steps; ++step) {
      std::fill(below.begin(), below.end(), 0);
      for (std::size_t k = 0; k < local.size(); ++k)
        if (const int n = node_of[k]; n >= 0 && local[k].x[axis[std::size_t(n)]] < 0.5 * (low[std::size_t(n)] + high[std::size_t(n)]))
          below[std::size_t(n)] += local[k].weight;
      MPI_Allreduce(MPI_IN_PLACE, below.data(), int(m), MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
      ++collectives_;
      for (std::size_t n = 0; n < m; ++n) {
        const Node& node = level[n];
        const int mid = node.lo + (node.hi - node.lo) / 2;
        const double at = 0.5 * (low[n] + high[n]);
        (below[n] * (node.hi - node.lo) < total[n] * (mid - node.lo) ? low[n] : high[n]) = at;
      }
    }
    std::vector<Node> next;
    std::vector<int> child(2 * m, -1);  // per node: its lower and upper child's index in `next`
    for (std::size_t n = 0; n < m; ++n) {
      const Node& node = level[n];
      const int mid = node.lo + (node.hi - node.lo) / 2;
      Cut& cut = cuts_[std::size_t(node.tree)];
      cut.axis = axis[n], cut.at = high[n];
      Box lower = node.box, upper = node.box;
      lower.hi[cut.axis] = upper.lo[cut.axis] = cut.at;
      const std::pair<int, int> halves[2] = {{node.lo, mid}, {mid, node.hi}};
      for (int side = 0; side < 2; ++side) {
        const int tree = int(cuts_.size());
        cuts_.emplace_back();
        (side == 0 ? cuts_[std::size_t(node.tree)].below : cuts_[std::size_t(node.tree)].above) = tree;
        const auto [lo, hi] = halves[side];
        const Box& box = side == 0 ? lower : upper;
        if (hi - lo == 1) {
          cuts_[std::size_t(tree)].rank = lo;
          boxes_[std::size_t(lo)] = box;
        } else {
          child[2 * n + std::size_t(side)] = int(next.size());
          next.push_back({lo, hi, tree, box});
        }
      }
    }
    for (std::size_t k = 0; k < local.size(); ++k)
      if (const int n = node_of[k]; n >= 0)
        node_of[k] = child[2 * std::size_t(n) + (local[k].x[axis[std::size_t(n)]] < high[std::size_t(n)] ? 0 : 1)];
    level.swap(next);
  }
}

void RcbPartition::save(std::vector<char>& out) const {
  put(out, std::uint64_t(cuts_.size()));
  for (const Cut& c : cuts_) put(out, c.axis), put(out, c.at), put(out, c.below), put(out, c.above), put(out, c.rank);
  put(out, std::uint64_t(boxes_.size()));
  for (const Box& b : boxes_) put(out, b.lo), put(out, b.hi);
}

void RcbPartition::restore(const char*& at) {
  cuts_.resize(take<std::uint64_t>(at));
  for (Cut& c : cuts_)
    c.axis = take<int>(at), c.at = take<double>(at), c.below = take<int>(at), c.above = take<int>(at), c.rank = take<int>(at);
  boxes_.resize(take<std::uint64_t>(at));
  for (Box& b : boxes_) b.lo = take<Vec3>(at), b.hi = take<Vec3>(at);
}

}  // namespace dem
