#include "dem/mpi_exchange.hpp"

#include <mpi.h>

#include <algorithm>
#include <array>
#include <exception>
#include <limits>
#include <stdexcept>

#include "dem/distributed.hpp"
#include "dem/model.hpp"
#include "dem/rcb_partition.hpp"
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
class MpiExchange final : public Exchange {
 public:
  explicit MpiExchange(std::size_t largest_message) : largest_message_(largest_message) {
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks_);
  }
  int rank() const override { return rank_; }
  int ranks() const override { return ranks_; }
  double max(double local) override {
    double global = 0;
    MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    ++collectives_;
    return global;
  }
  double sum(double local) override {
    double total = 0;
    for (double v : all_gather({local})) total += v;  // rank order: the same bits every run
    return total;
  }
  std::int64_t sum(std::int64_t local) override {
    std::int64_t global = 0;
    MPI_Allreduce(&local, &global, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
    ++collectives_;
    return global;
  }
  std::vector<double> all_gather(const std::vector<double>& local) override;
  std::vector<double> agree(const State& s, const std::vector<double>& local) override;
  void in_turn(const std::function<void()>& work) override;
  std::int64_t global_collectives() const override { return collectives_ + cuts_.collectives(); }
  std::int64_t cuts() const override { return cut_count_; }
  std::int64_t messages_sent() const override { return messages_sent_; }
  std::int64_t bytes_sent() const override { return bytes_sent_; }
  std::vector<char> gather(const std::vector<char>& local) override;
  void barrier() override {
    MPI_Barrier(MPI_COMM_WORLD);
    ++collectives_;
  }
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
  std::vector<char> saved() const override;
  void restore(const char* bytes, std::size_t size) override;

 private:
  struct Outgoing {
    int to;
    const std::vector<char>* bytes;
  };
  // Sends each buffer of `out` to its rank and receives one from every rank of `from`: returns
  // those, concatenated in `from`'s order. Every transfer between ranks goes through here. MPI
  // counts bytes in int, which a gathered state or a migration can outgrow (a gather of 20 M
  // grains is over 2 GiB), and Open MPI 4.1 has no MPI_Count variants: the sizes travel as 64-bit
  // counts, the bytes in messages of at most largest_message_.
  // `at`, when given, receives where each rank's bytes begin in the result (one more than `from`).
  std::vector<char> transfer(const std::vector<Outgoing>& out, const std::vector<int>& from,
                             std::vector<std::size_t>* at = nullptr);
  // The bytes alone, when the receiver knows how many each rank of `from` sends (ascending offsets
  // into the result, one more than `from`).
  std::vector<char> move_bytes(const std::vector<Outgoing>& out, const std::vector<int>& from,
                               const std::vector<std::size_t>& at);

  // Each rank's buffer to it; returns what every rank sent here, in rank order.
  std::vector<char> all_to_all(const std::vector<std::vector<char>>& out);
  // The same when only the neighbouring subdomains' buffers can hold anything: messages to and
  // from them alone, so that a step's cost does not grow with the number of ranks.
  std::vector<char> with_neighbours(const std::vector<std::vector<char>>& out, std::vector<std::size_t>* at = nullptr);
  void migrate(State& s);
  void send_ghosts(const Model& model, State& s);

  std::size_t largest_message_;
  int rank_ = 0, ranks_ = 1;
  RcbPartition cuts_;
  std::vector<std::vector<std::int32_t>> send_;  // [ranks] owned grains ghosted there, in send order
  // The other ranks whose boxes lie within ghost reach of this one's, ascending: the only ones a
  // ghost goes to or a grain migrates to between two cuts.
  std::vector<int> neighbours_;
  // Where each neighbour's ghosts begin among this rank's (offsets in bytes of GhostMotion, one
  // more than neighbours_): fixed from one rebuild to the next, so that a ghost update is one
  // round of messages.
  std::vector<std::size_t> ghost_at_;
  std::vector<std::vector<char>> ghost_out_;  // [ranks] the update's buffers, kept from step to step
  // The largest radius and member offset of all grains, and the ghost reach they give: the same
  // from one cut to the next (grains come or go only with a cut, exchange.hpp).
  double reach_ = 0, outside_ = 0;
  bool recut_ = false;  // the last migrate cut anew
  // From the step's agree(): the heaviest rank's work and the mean, for the rebuild it may call.
  bool agreed_ = false;
  double heaviest_ = 0, mean_ = 0;
  // This rank's work (work_of), the same from one build to the next: weighed at the first agree
  // after a migration (keyed by the list's build count and sizes), not in every step's.
  double work_ = 0;
  std::array<std::int64_t, 3> work_of_list_{-1, -1, -1};
  std::int64_t collectives_ = 0, cut_count_ = 0, messages_sent_ = 0, bytes_sent_ = 0;
};

// The work a rank's grains carry, as migrate weighs it: each active grain, and its listed pairs.
double work_of(const State& s) {
  const NeighbourList& nl = s.neighbours;
  const bool listed = nl.row_start.size() == s.size() + 1;
  std::int64_t work = 0;
  for (std::size_t i = 0; i < s.owned(); ++i)
    if (s.active[i]) work += 1 + (listed ? std::int64_t(nl.row_start[i + 1] - nl.row_start[i]) : 0);
  return double(work);
}

std::vector<double> MpiExchange::all_gather(const std::vector<double>& local) {
  std::vector<double> all(local.size() * std::size_t(ranks_));
  MPI_Allgather(local.data(), int(local.size()), MPI_DOUBLE, all.data(), int(local.size()), MPI_DOUBLE, MPI_COMM_WORLD);
  ++collectives_;
  return all;
}

std::vector<double> MpiExchange::agree(const State& s, const std::vector<double>& local) {
  const std::array<std::int64_t, 3> list{s.neighbours.builds, std::int64_t(s.owned()), std::int64_t(s.neighbours.row_start.size())};
  if (list != work_of_list_) work_ = work_of(s), work_of_list_ = list;
  std::vector<double> mine = local;
  mine.push_back(work_);
  const std::vector<double> all = all_gather(mine);
  const std::size_t k = mine.size();
  std::vector<double> theirs;
  theirs.reserve(local.size() * std::size_t(ranks_));
  double total = 0;
  heaviest_ = 0;
  for (std::size_t r = 0; r < std::size_t(ranks_); ++r) {
    theirs.insert(theirs.end(), all.begin() + std::ptrdiff_t(r * k), all.begin() + std::ptrdiff_t(r * k + k - 1));
    heaviest_ = std::max(heaviest_, all[r * k + k - 1]), total += all[r * k + k - 1];
  }
  mean_ = total / ranks_;
  agreed_ = true;
  return theirs;
}

// The token is one byte; a failing rank passes it on before it rethrows, so that no rank waits
// for ever.
void MpiExchange::in_turn(const std::function<void()>& work) {
  char token = 0;
  if (rank_ > 0) MPI_Recv(&token, 1, MPI_CHAR, rank_ - 1, 2, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  std::exception_ptr failure;
  try {
    work();
  } catch (...) {
    failure = std::current_exception();
  }
  if (rank_ + 1 < ranks_) MPI_Send(&token, 1, MPI_CHAR, rank_ + 1, 2, MPI_COMM_WORLD);
  if (failure) std::rethrow_exception(failure);
}

std::vector<char> MpiExchange::saved() const {
  std::vector<char> out;
  cuts_.save(out);
  put(out, std::uint64_t(neighbours_.size()));
  for (std::size_t k = 0; k < neighbours_.size(); ++k) put(out, neighbours_[k]), put(out, std::uint64_t(ghost_at_[k + 1] - ghost_at_[k]));
  for (const auto& list : send_) {
    put(out, std::uint64_t(list.size()));
    for (std::int32_t i : list) put(out, i);
  }
  put(out, reach_), put(out, outside_);
  return out;
}

void MpiExchange::restore(const char* bytes, std::size_t size) {
  const char* at = bytes;
  cuts_.restore(at);
  neighbours_.resize(take<std::uint64_t>(at));
  ghost_at_.assign(neighbours_.size() + 1, 0);
  for (std::size_t k = 0; k < neighbours_.size(); ++k) neighbours_[k] = take<int>(at), ghost_at_[k + 1] = ghost_at_[k] + take<std::uint64_t>(at);
  send_.assign(std::size_t(ranks_), {});
  for (auto& list : send_) {
    list.resize(take<std::uint64_t>(at));
    for (std::int32_t& i : list) i = take<std::int32_t>(at);
  }
  reach_ = take<double>(at), outside_ = take<double>(at);
  if (at != bytes + size) throw std::logic_error("MpiExchange::restore: the saved exchange has another size");
}

std::vector<char> MpiExchange::transfer(const std::vector<Outgoing>& out, const std::vector<int>& from,
                                        std::vector<std::size_t>* offsets) {
  std::vector<std::uint64_t> sizes(out.size()), receive_sizes(from.size());
  std::vector<MPI_Request> requests;
  for (std::size_t k = 0; k < from.size(); ++k)
    MPI_Irecv(&receive_sizes[k], 1, MPI_UINT64_T, from[k], 0, MPI_COMM_WORLD, &requests.emplace_back());
  for (std::size_t k = 0; k < out.size(); ++k) {
    sizes[k] = out[k].bytes->size();
    MPI_Isend(&sizes[k], 1, MPI_UINT64_T, out[k].to, 0, MPI_COMM_WORLD, &requests.emplace_back());
    ++messages_sent_, bytes_sent_ += std::int64_t(sizeof sizes[k]);
  }
  MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
  std::vector<std::size_t> at(from.size() + 1, 0);
  for (std::size_t k = 0; k < from.size(); ++k) at[k + 1] = at[k] + std::size_t(receive_sizes[k]);
  if (offsets) *offsets = at;
  return move_bytes(out, from, at);
}

std::vector<char> MpiExchange::move_bytes(const std::vector<Outgoing>& out, const std::vector<int>& from,
                                          const std::vector<std::size_t>& at) {
  std::vector<char> received(at.back());
  std::vector<MPI_Request> requests;
  // Both sides cut a buffer alike, from its size; MPI keeps the order of the messages between two
  // ranks with one tag, so that the k-th piece sent meets the k-th receive.
  const auto piece = [&](std::size_t size, std::size_t offset) { return int(std::min(size - offset, largest_message_)); };
  for (std::size_t k = 0; k < from.size(); ++k)
    for (std::size_t o = 0; o < at[k + 1] - at[k]; o += largest_message_)
      MPI_Irecv(received.data() + at[k] + o, piece(at[k + 1] - at[k], o), MPI_BYTE, from[k], 1, MPI_COMM_WORLD,
                &requests.emplace_back());
  for (const Outgoing& o : out)
    for (std::size_t b = 0; b < o.bytes->size(); b += largest_message_) {
      MPI_Isend(o.bytes->data() + b, piece(o.bytes->size(), b), MPI_BYTE, o.to, 1, MPI_COMM_WORLD, &requests.emplace_back());
      ++messages_sent_, bytes_sent_ += piece(o.bytes->size(), b);
    }
  MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
  return received;
}

std::vector<char> MpiExchange::all_to_all(const std::vector<std::vector<char>>& out) {
  ++collectives_;  // point to point, but with every rank
  std::vector<Outgoing> sending;
  std::vector<int> every(static_cast<std::size_t>(ranks_));
  for (int r = 0; r < ranks_; ++r) sending.push_back({r, &out[std::size_t(r)]}), every[std::size_t(r)] = r;
  return transfer(sending, every);
}

std::vector<char> MpiExchange::with_neighbours(const std::vector<std::vector<char>>& out, std::vector<std::size_t>* at) {
  std::vector<Outgoing> sending;
  for (int r : neighbours_) sending.push_back({r, &out[std::size_t(r)]});
  return transfer(sending, neighbours_, at);
}

std::vector<char> MpiExchange::gather(const std::vector<char>& local) {
  ++collectives_;
  std::vector<int> every;
  for (int r = 0; rank_ == 0 && r < ranks_; ++r) every.push_back(r);
  return transfer({{0, &local}}, every);
}

void MpiExchange::redistribute(const Model& model, State& s) {
  migrate(s);
  send_ghosts(model, s);
}

// The subdomains' weights: a grain costs itself and its listed pairs; a clump, its members
// together, at its body's centre.
std::vector<WeightedPoint> weighted_points(const State& s) {
  const NeighbourList& nl = s.neighbours;
  const Bodies& B = s.bodies;
  const bool listed = nl.row_start.size() == s.size() + 1;
  const auto cost = [&](std::size_t i) { return 1 + (listed ? std::int64_t(nl.row_start[i + 1] - nl.row_start[i]) : 0); };
  std::vector<WeightedPoint> points;
  for (std::size_t i = 0; i < s.owned(); ++i)
    if (s.active[i] && s.body[i] < 0) points.push_back({s.x[i], cost(i)});
  for (std::size_t b = 0; b < B.size(); ++b)
    if (B.active[b]) {
      std::int64_t weight = 0;
      for (std::int32_t k = B.member_start[b]; k < B.member_start[b + 1]; ++k) weight += cost(std::size_t(B.member[std::size_t(k)]));
      points.push_back({B.x[b], weight});
    }
  return points;
}

// The pair histories at a migration: a grain that leaves takes its own view of each of its pairs
// (leaving[k] for the k-th leaving grain; a pair of two leaving grains goes with both, as either
// may be sent elsewhere); one that stays keeps, by id, one view of each pair with a ghost or a
// leaving grain, which the rebuild matches either way. A pair of two staying grains stays in the
// list, read by index at the rebuild (State::renumbered). Before the first list, the histories
// are those carried in already.
struct MigratingHistories {
  std::vector<CarriedPair> staying;
  std::vector<std::vector<CarriedPair>> leaving;
};
MigratingHistories migrating_histories(const State& s, const std::vector<int>& to, int rank,
                                       const std::vector<std::int32_t>& leaving_index, std::size_t leaving_count) {
  MigratingHistories h;
  h.leaving.resize(leaving_count);
  const std::size_t owned = s.owned();
  const auto keep = [&](std::size_t i, const CarriedPair& c) {
    if (to[i] == rank) h.staying.push_back(c);
    else h.leaving[std::size_t(leaving_index[i])].push_back(c);
  };
  for_each_history(s, [&](std::size_t i, std::int64_t j, const CarriedPair& c) {
    const bool partner_owned = j >= 0 && std::size_t(j) < owned;
    if (to[i] == rank && partner_owned && to[std::size_t(j)] == rank) return;  // both stay: it stays in the list
    keep(i, c);
    if (partner_owned) keep(std::size_t(j), other_view(c));
  });
  return h;
}

// The grains in a migration's buffer (its layout: migrate).
std::size_t arrivals(const std::vector<char>& received) {
  std::size_t grains = 0;
  const auto skip_grain = [&](const char*& at) {
    const Migrant m = take<Migrant>(at);
    at += (m.near_wall ? wall_slots_per_particle * sizeof(WallSlot) : 0) + std::size_t(m.pairs) * sizeof(CarriedPair);
    ++grains;
  };
  for (const char* at = received.data(); at < received.data() + received.size();) {
    const auto members = take<std::int32_t>(at);
    if (members > 0) at += sizeof(BodyRecord) + std::size_t(members) * sizeof(Vec3);
    for (std::int32_t k = 0; k < std::max(members, 1); ++k) skip_grain(at);
  }
  return grains;
}

// Grains move by units: a free grain goes where its centre lies, a clump where its body's centre
// lies, with all its members (the body's force is summed from its members' on one rank).
void MpiExchange::migrate(State& s) {
  const std::size_t owned = s.owned();
  const NeighbourList& nl = s.neighbours;
  const Bodies& B = s.bodies;
  const bool listed = nl.row_start.size() == s.size() + 1;
  // Cut anew at the first call, or when the heaviest rank carries more than 1.2 times the mean
  // (weighed by the step's agree(), or here when no step came before: initialize()). Also whenever
  // the grains come without a list (shared anew, resumed, a round inserted; every rank alike): the
  // cuts then follow from the grains alone, not from what the exchange did before.
  if (!agreed_) {
    const std::vector<double> work = all_gather({work_of(s)});
    heaviest_ = *std::max_element(work.begin(), work.end());
    mean_ = 0;
    for (double w : work) mean_ += w / ranks_;
  }
  agreed_ = false;
  work_of_list_ = {-1, -1, -1};  // the grains change here: weighed afresh at the next agree
  recut_ = cuts_.empty() || !listed || heaviest_ > 1.2 * mean_;
  if (recut_) cuts_.cut(weighted_points(s)), ++cut_count_;

  // Where each owned grain goes; a lost grain stays where it was lost: it takes part in nothing.
  // Between two cuts a grain moves less than half the skin between rebuilds, less than the ghost
  // reach, so it migrates to a neighbour; after a cut every rank may send to every other.
  const auto destination = [&](bool active, const Vec3& x) {
    const int to = active ? cuts_.owner(x) : rank_;
    if (!recut_ && to != rank_ && !std::binary_search(neighbours_.begin(), neighbours_.end(), to))
      throw std::logic_error("migrate: a grain moved beyond the neighbouring subdomains between two rebuilds");
    return to;
  };
  std::vector<int> to(owned, rank_);
  for (std::size_t i = 0; i < owned; ++i)
    if (s.body[i] < 0) to[i] = destination(s.active[i] != 0, s.x[i]);
  for (std::size_t b = 0; b < B.size(); ++b) {
    const int d = destination(B.active[b] != 0, B.x[b]);
    for (std::int32_t k = B.member_start[b]; k < B.member_start[b + 1]; ++k) to[std::size_t(B.member[std::size_t(k)])] = d;
  }
  std::vector<std::int32_t> leaving_index(owned, -1);
  std::size_t leaving = 0;
  for (std::size_t i = 0; i < owned; ++i)
    if (to[i] != rank_) leaving_index[i] = std::int32_t(leaving++);
  // What each grain takes along: its pairs' histories (as it sees them), its wall contacts.
  MigratingHistories histories = migrating_histories(s, to, rank_, leaving_index, leaving);
  std::vector<const WallSlot*> slots_of(owned, nullptr);
  if (s.wall_slots.size() == nl.near_wall.size() * wall_slots_per_particle)
    for (std::size_t q = 0; q < nl.near_wall.size(); ++q) slots_of[std::size_t(nl.near_wall[q])] = &s.wall_slots[q * wall_slots_per_particle];

  std::vector<std::vector<char>> out(static_cast<std::size_t>(ranks_));
  std::vector<std::size_t> keep;
  keep.reserve(owned - leaving);
  Array<std::int32_t> near;
  Array<WallSlot> slots;
  const auto stay = [&](std::size_t i) {
    keep.push_back(i);
    if (slots_of[i]) {
      near.push_back(std::int32_t(keep.size() - 1));
      slots.insert(slots.end(), slots_of[i], slots_of[i] + wall_slots_per_particle);
    }
  };
  const auto send = [&](std::vector<char>& b, std::size_t i) {
    std::vector<CarriedPair>& pairs = histories.leaving[std::size_t(leaving_index[i])];
    put(b, Migrant{grain_record(s, i), std::int32_t(pairs.size()), std::uint8_t(slots_of[i] ? 1 : 0)});
    if (slots_of[i])
      for (int k = 0; k < wall_slots_per_particle; ++k) put(b, slots_of[i][k]);
    for (const CarriedPair& c : pairs) put(b, c);
    std::vector<CarriedPair>().swap(pairs);
  };
  // Each unit in the buffer: its member count (0: a free grain), for a clump its body and offsets,
  // then its grains.
  for (std::size_t i = 0; i < owned; ++i) {
    if (s.body[i] >= 0) continue;
    if (to[i] == rank_) {
      stay(i);
      continue;
    }
    put(out[std::size_t(to[i])], std::int32_t{0});
    send(out[std::size_t(to[i])], i);
  }
  for (std::size_t b = 0; b < B.size(); ++b) {
    const auto first = B.member_start[b], last = B.member_start[b + 1];
    const int d = to[std::size_t(B.member[std::size_t(first)])];
    if (d == rank_) {
      for (std::int32_t k = first; k < last; ++k) stay(std::size_t(B.member[std::size_t(k)]));
      continue;
    }
    std::vector<char>& buffer = out[std::size_t(d)];
    put(buffer, std::int32_t(last - first));
    put(buffer, body_record(B, b));
    for (std::int32_t k = first; k < last; ++k) put(buffer, B.offset[std::size_t(k)]);
    for (std::int32_t k = first; k < last; ++k) send(buffer, std::size_t(B.member[std::size_t(k)]));
  }
  histories.leaving = {};
  const std::vector<char> received = recut_ ? all_to_all(out) : with_neighbours(out);
  out = {};
  s.renumbered.assign(listed ? s.size() : 0, -1);
  for (std::size_t k = 0; listed && k < keep.size(); ++k) s.renumbered[keep[k]] = std::int32_t(k);
  keep_grains(s, keep);
  reserve_grains(s, keep.size() + arrivals(received));
  std::vector<CarriedPair>& carried = histories.staying;
  const auto arrive = [&](const char*& at) {
    const Migrant m = take<Migrant>(at);
    append_grain(s, m.grain);
    if (m.near_wall) {
      near.push_back(std::int32_t(s.size() - 1));
      for (int k = 0; k < wall_slots_per_particle; ++k) slots.push_back(take<WallSlot>(at));
    }
    for (std::int32_t k = 0; k < m.pairs; ++k) carried.push_back(take<CarriedPair>(at));
  };
  std::vector<Vec3> offset;
  std::vector<std::int32_t> member;
  for (const char* at = received.data(); at < received.data() + received.size();) {
    const auto members = take<std::int32_t>(at);
    if (members == 0) {
      arrive(at);
      continue;
    }
    const BodyRecord body = take<BodyRecord>(at);
    offset.clear(), member.clear();
    for (std::int32_t k = 0; k < members; ++k) offset.push_back(take<Vec3>(at));
    for (std::int32_t k = 0; k < members; ++k) arrive(at), member.push_back(std::int32_t(s.size() - 1));
    append_body(s, body, member.data(), offset.data());
  }
  s.ghosts = 0;
  s.neighbours.near_wall.swap(near);
  s.wall_slots.swap(slots);
  s.carried_pairs.swap(carried);
}

// Every owned grain within reach of another rank's subdomain is copied there: reach 2 r_max +
// skin, the farthest a listed partner of a grain inside that subdomain can be at the build, and
// with clumps the farthest a member lies from its body's centre, which alone lies in the box.
void MpiExchange::send_ghosts(const Model& model, State& s) {
  if (recut_) {
    double r_max = 0, outside = 0;
    for (std::size_t i = 0; i < s.size(); ++i) r_max = std::max(r_max, s.radius[i]);
    const Bodies& B = s.bodies;
    for (std::size_t b = 0; b < B.size(); ++b)
      for (std::int32_t k = B.member_start[b]; k < B.member_start[b + 1]; ++k)
        outside = std::max(outside, (s.x[std::size_t(B.member[std::size_t(k)])] - B.x[b]).norm());
    outside_ = max(outside);
    reach_ = 2 * max(r_max) + model.skin + outside_;
  }
  // The owned grains lie in this rank's box, or as far outside it as a member from its centre:
  // only boxes within reach of that can want them.
  neighbours_.clear();
  const std::vector<Box>& boxes = cuts_.boxes();
  for (int r = 0; r < ranks_; ++r)
    if (r != rank_ && boxes[std::size_t(r)].distance(boxes[std::size_t(rank_)]) < reach_ + outside_) neighbours_.push_back(r);
  send_.assign(std::size_t(ranks_), {});
  std::vector<std::vector<char>> out(static_cast<std::size_t>(ranks_));
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (!s.active[i]) continue;
    for (int r : neighbours_)
      if (boxes[std::size_t(r)].distance(s.x[i]) < reach_) {
        send_[std::size_t(r)].push_back(std::int32_t(i));
        put(out[std::size_t(r)], grain_record(s, i));
      }
  }
  const std::vector<char> received = with_neighbours(out, &ghost_at_);
  for (std::size_t& at : ghost_at_) at = at / sizeof(GrainRecord) * sizeof(GhostMotion);
  reserve_grains(s, s.size() + received.size() / sizeof(GrainRecord));
  for (const char* at = received.data(); at < received.data() + received.size(); ++s.ghosts) {
    append_grain(s, take<GrainRecord>(at));
  }
}

// One round of messages: each neighbour sends as many ghosts as at the rebuild, in the same order.
void MpiExchange::update_ghosts(State& s) {
  ghost_out_.resize(std::size_t(ranks_));
  std::vector<Outgoing> sending;
  for (int r : neighbours_) {
    std::vector<char>& buffer = ghost_out_[std::size_t(r)];
    buffer.clear();
    for (std::int32_t i : send_[std::size_t(r)]) put(buffer, GhostMotion{s.x[std::size_t(i)], s.v[std::size_t(i)], s.w[std::size_t(i)]});
    sending.push_back({r, &buffer});
  }
  const std::vector<char> received = move_bytes(sending, neighbours_, ghost_at_);
  std::size_t g = s.owned();
  for (const char* at = received.data(); at < received.data() + received.size(); ++g) {
    const GhostMotion m = take<GhostMotion>(at);
    s.x[g] = m.x, s.v[g] = m.v, s.w[g] = m.w;
  }
}

}  // namespace

std::shared_ptr<Exchange> make_mpi_exchange(std::size_t largest_message) {
  return std::make_shared<MpiExchange>(std::clamp<std::size_t>(largest_message, 1, std::numeric_limits<int>::max()));
}

}  // namespace dem
