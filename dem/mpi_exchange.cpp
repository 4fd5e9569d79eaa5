#include "dem/mpi_exchange.hpp"

#include <mpi.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <type_traits>

#include "core/error.hpp"
#include "dem/distributed.hpp"
#include "dem/model.hpp"
#include "dem/state.hpp"

namespace dem {

namespace {

// A grain moving to another rank; its K wall slots (when near a wall) and `pairs` histories follow.
struct Migrant {
  GrainRecord grain;
  std::int32_t pairs;
  std::uint8_t near_wall;
};
// A ghost's motion every step after the rebuild that sent its copy (a GrainRecord).
struct GhostMotion {
  Vec3 x, v, w;
};
// A grain as the partitioner weighs it.
struct WeightedPoint {
  Vec3 x;
  double weight;
  std::int64_t id;
};

// The subdomains: a tree of cuts, each leaf a rank; its boxes tile all of space.
struct Cut {
  int axis = -1;  // -1: a leaf
  double at = 0;
  int below = -1, above = -1, rank = -1;
};

struct Box {
  Vec3 lo = Vec3::Constant(-std::numeric_limits<double>::infinity()), hi = -lo;
  double distance(const Vec3& p) const {
    return (lo - p).cwiseMax(p - hi).cwiseMax(0.0).norm();
  }
};

class MpiExchange final : public Exchange {
 public:
  MpiExchange() {
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks_);
  }
  int rank() const override { return rank_; }
  int ranks() const override { return ranks_; }
  double max(double local) override {
    double global = 0;
    MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    return global;
  }
  double sum(double local) override {
    std::vector<double> all(static_cast<std::size_t>(ranks_));
    MPI_Allgather(&local, 1, MPI_DOUBLE, all.data(), 1, MPI_DOUBLE, MPI_COMM_WORLD);
    double total = 0;
    for (double v : all) total += v;  // rank order: the same bits every run
    return total;
  }
  std::int64_t sum(std::int64_t local) override {
    std::int64_t global = 0;
    MPI_Allreduce(&local, &global, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
    return global;
  }
  std::vector<char> gather(const std::vector<char>& local) override;
  void barrier() override { MPI_Barrier(MPI_COMM_WORLD); }
  void redistribute(const Model& model, State& s) override;
  void reordered(const std::vector<std::int32_t>& new_index) override {
    for (auto& list : send_)
      for (std::int32_t& i : list) i = new_index[std::size_t(i)];
  }
  void update_ghosts(State& s) override;
  std::size_t ghost_bytes_per_step() const override {
    std::size_t grains = 0;
    for (const auto& list : send_) grains += list.size();
    return grains * sizeof(GhostMotion);
  }

 private:
  // Each rank's buffer to it; returns what every rank sent here, in rank order.
  std::vector<char> all_to_all(const std::vector<std::vector<char>>& out) const;
  void partition(const std::vector<WeightedPoint>& local);
  int bisect(std::vector<WeightedPoint>& points, std::size_t first, std::size_t last, int lo, int hi, const Box& box);
  int owner(const Vec3& x) const {
    int node = 0;
    while (cuts_[std::size_t(node)].axis >= 0) {
      const Cut& c = cuts_[std::size_t(node)];
      node = x[c.axis] < c.at ? c.below : c.above;
    }
    return cuts_[std::size_t(node)].rank;
  }
  void migrate(State& s);
  void send_ghosts(const Model& model, State& s);

  int rank_ = 0, ranks_ = 1;
  std::vector<Cut> cuts_;
  std::vector<Box> boxes_;                   // [ranks]
  std::vector<std::vector<std::int32_t>> send_;  // [ranks] owned grains ghosted there, in send order
};

std::vector<char> MpiExchange::all_to_all(const std::vector<std::vector<char>>& out) const {
  std::vector<int> send_counts(static_cast<std::size_t>(ranks_)), receive_counts(static_cast<std::size_t>(ranks_));
  for (std::size_t r = 0; r < out.size(); ++r) send_counts[r] = int(out[r].size());
  MPI_Alltoall(send_counts.data(), 1, MPI_INT, receive_counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
  std::vector<int> send_at(static_cast<std::size_t>(ranks_), 0), receive_at(static_cast<std::size_t>(ranks_), 0);
  for (std::size_t r = 1; r < std::size_t(ranks_); ++r) {
    send_at[r] = send_at[r - 1] + send_counts[r - 1];
    receive_at[r] = receive_at[r - 1] + receive_counts[r - 1];
  }
  std::vector<char> sending, received(std::size_t(receive_at.back() + receive_counts.back()));
  for (const auto& b : out) sending.insert(sending.end(), b.begin(), b.end());
  MPI_Alltoallv(sending.data(), send_counts.data(), send_at.data(), MPI_BYTE, received.data(), receive_counts.data(),
                receive_at.data(), MPI_BYTE, MPI_COMM_WORLD);
  return received;
}

std::vector<char> MpiExchange::gather(const std::vector<char>& local) {
  const int bytes = int(local.size());
  std::vector<int> counts(static_cast<std::size_t>(ranks_)), at(static_cast<std::size_t>(ranks_), 0);
  MPI_Gather(&bytes, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  for (std::size_t r = 1; r < std::size_t(ranks_); ++r) at[r] = at[r - 1] + counts[r - 1];
  std::vector<char> all(rank_ == 0 ? std::size_t(at.back() + counts.back()) : 0);
  MPI_Gatherv(local.data(), bytes, MPI_BYTE, all.data(), counts.data(), at.data(), MPI_BYTE, 0, MPI_COMM_WORLD);
  return all;
}

// Recursive coordinate bisection of every rank's grains, computed alike on every rank from the
// gathered points: each cut across the longest extent of its grains, where the weight below it
// is the share of the ranks below it.
void MpiExchange::partition(const std::vector<WeightedPoint>& local) {
  const int bytes = int(local.size() * sizeof(WeightedPoint));
  std::vector<int> counts(static_cast<std::size_t>(ranks_)), at(static_cast<std::size_t>(ranks_), 0);
  MPI_Allgather(&bytes, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
  for (std::size_t r = 1; r < std::size_t(ranks_); ++r) at[r] = at[r - 1] + counts[r - 1];
  std::vector<WeightedPoint> all(std::size_t(at.back() + counts.back()) / sizeof(WeightedPoint));
  MPI_Allgatherv(local.data(), bytes, MPI_BYTE, all.data(), counts.data(), at.data(), MPI_BYTE, MPI_COMM_WORLD);
  cuts_.clear();
  boxes_.assign(std::size_t(ranks_), Box{});
  bisect(all, 0, all.size(), 0, ranks_, Box{});
}

int MpiExchange::bisect(std::vector<WeightedPoint>& points, std::size_t first, std::size_t last, int lo, int hi, const Box& box) {
  const int node = int(cuts_.size());
  cuts_.emplace_back();
  if (hi - lo == 1) {
    cuts_[std::size_t(node)].rank = lo;
    boxes_[std::size_t(lo)] = box;
    return node;
  }
  const int mid = lo + (hi - lo) / 2;
  Vec3 low = Vec3::Constant(std::numeric_limits<double>::infinity()), high = -low;
  for (std::size_t k = first; k < last; ++k) low = low.cwiseMin(points[k].x), high = high.cwiseMax(points[k].x);
  int axis = 0;
  double cut = std::clamp(0.0, box.lo[0], box.hi[0]);  // no grains: any cut will do
  std::size_t split = first;
  if (last > first) {
    (high - low).maxCoeff(&axis);
    std::sort(points.begin() + std::ptrdiff_t(first), points.begin() + std::ptrdiff_t(last),
              [axis](const WeightedPoint& a, const WeightedPoint& b) {
                return a.x[axis] != b.x[axis] ? a.x[axis] < b.x[axis] : a.id < b.id;
              });
    double total = 0;
    for (std::size_t k = first; k < last; ++k) total += points[k].weight;
    const double below = total * double(mid - lo) / double(hi - lo);
    double sum = 0;
    while (split < last && sum + 0.5 * points[split].weight < below) sum += points[split++].weight;
    cut = split == first ? points[first].x[axis] : split == last ? std::nextafter(points[last - 1].x[axis], box.hi[axis])
                                                                 : 0.5 * (points[split - 1].x[axis] + points[split].x[axis]);
  }
  Box lower = box, upper = box;
  lower.hi[axis] = upper.lo[axis] = cut;
  const int below_node = bisect(points, first, split, lo, mid, lower);
  const int above_node = bisect(points, split, last, mid, hi, upper);
  Cut& c = cuts_[std::size_t(node)];
  c.axis = axis, c.at = cut, c.below = below_node, c.above = above_node;
  return node;
}

void MpiExchange::redistribute(const Model& model, State& s) {
  if (s.bodies.size() > 0)
    throw diefill::InputError("mpirun", "ranks", "clump grains are not split over MPI ranks yet",
                              "Run clump grains on one process (threads), or use spheres");
  migrate(s);
  send_ghosts(model, s);
}

void MpiExchange::migrate(State& s) {
  const std::size_t owned = s.owned();
  const NeighbourList& nl = s.neighbours;
  const bool listed = nl.row_start.size() == s.size() + 1;
  // What each owned grain takes along: its pairs' histories (as it sees them), its wall contacts.
  const std::vector<std::vector<CarriedPair>> pairs_of = contact_histories(s);
  std::vector<const WallSlot*> slots_of(owned, nullptr);
  std::vector<WeightedPoint> points;
  // The cost of a grain: its listed pairs, and itself.
  for (std::size_t i = 0; i < owned; ++i)
    if (s.active[i]) points.push_back({s.x[i], 1.0 + (listed ? double(nl.row_start[i + 1] - nl.row_start[i]) : 0.0), s.id[i]});
  if (s.wall_slots.size() == nl.near_wall.size() * wall_slots_per_particle)
    for (std::size_t q = 0; q < nl.near_wall.size(); ++q) slots_of[std::size_t(nl.near_wall[q])] = &s.wall_slots[q * wall_slots_per_particle];

  // Cut anew at the first call, or when the heaviest rank carries more than 1.2 times the mean.
  double work = 0;
  for (const WeightedPoint& p : points) work += p.weight;
  const double heaviest = max(work), mean = sum(work) / ranks_;
  if (cuts_.empty() || heaviest > 1.2 * mean) partition(points);

  std::vector<std::vector<char>> out(static_cast<std::size_t>(ranks_));
  std::vector<std::size_t> keep;
  Array<std::int32_t> near;
  Array<WallSlot> slots;
  std::vector<CarriedPair> carried;
  const auto carry = [&](std::size_t i) {
    if (slots_of[i]) {
      near.push_back(std::int32_t(keep.size() - 1));
      slots.insert(slots.end(), slots_of[i], slots_of[i] + wall_slots_per_particle);
    }
    carried.insert(carried.end(), pairs_of[i].begin(), pairs_of[i].end());
  };
  for (std::size_t i = 0; i < owned; ++i) {
    // A lost grain stays where it was lost: it takes part in nothing.
    const int to = s.active[i] ? owner(s.x[i]) : rank_;
    if (to == rank_) {
      keep.push_back(i);
      carry(i);
      continue;
    }
    std::vector<char>& b = out[std::size_t(to)];
    put(b, Migrant{grain_record(s, i), std::int32_t(pairs_of[i].size()), std::uint8_t(slots_of[i] ? 1 : 0)});
    if (slots_of[i])
      for (int k = 0; k < wall_slots_per_particle; ++k) put(b, slots_of[i][k]);
    for (const CarriedPair& c : pairs_of[i]) put(b, c);
  }
  const std::vector<char> received = all_to_all(out);
  keep_grains(s, keep);
  for (const char* at = received.data(); at < received.data() + received.size();) {
    const Migrant m = take<Migrant>(at);
    append_grain(s, m.grain);
    if (m.near_wall) {
      near.push_back(std::int32_t(s.size() - 1));
      for (int k = 0; k < wall_slots_per_particle; ++k) slots.push_back(take<WallSlot>(at));
    }
    for (std::int32_t k = 0; k < m.pairs; ++k) carried.push_back(take<CarriedPair>(at));
  }
  s.ghosts = 0;
  s.neighbours.near_wall.swap(near);
  s.wall_slots.swap(slots);
  s.carried_pairs.swap(carried);
}

// Every owned grain within reach of another rank's subdomain is copied there: reach 2 r_max +
// skin, the farthest a listed partner of a grain inside that subdomain can be at the build.
void MpiExchange::send_ghosts(const Model& model, State& s) {
  double r_max = 0;
  for (std::size_t i = 0; i < s.size(); ++i) r_max = std::max(r_max, s.radius[i]);
  const double reach = 2 * max(r_max) + model.skin;
  send_.assign(std::size_t(ranks_), {});
  std::vector<std::vector<char>> out(static_cast<std::size_t>(ranks_));
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (!s.active[i]) continue;
    for (int r = 0; r < ranks_; ++r)
      if (r != rank_ && boxes_[std::size_t(r)].distance(s.x[i]) < reach) {
        send_[std::size_t(r)].push_back(std::int32_t(i));
        put(out[std::size_t(r)], grain_record(s, i));
      }
  }
  const std::vector<char> received = all_to_all(out);
  for (const char* at = received.data(); at < received.data() + received.size(); ++s.ghosts) {
    append_grain(s, take<GrainRecord>(at));
  }
}

void MpiExchange::update_ghosts(State& s) {
  std::vector<std::vector<char>> out(static_cast<std::size_t>(ranks_));
  for (std::size_t r = 0; r < send_.size(); ++r)
    for (std::int32_t i : send_[r]) put(out[r], GhostMotion{s.x[std::size_t(i)], s.v[std::size_t(i)], s.w[std::size_t(i)]});
  const std::vector<char> received = all_to_all(out);
  std::size_t g = s.owned();
  for (const char* at = received.data(); at < received.data() + received.size(); ++g) {
    const GhostMotion m = take<GhostMotion>(at);
    s.x[g] = m.x, s.v[g] = m.v, s.w[g] = m.w;
  }
}

}  // namespace

std::shared_ptr<Exchange> make_mpi_exchange() { return std::make_shared<MpiExchange>(); }

}  // namespace dem
