#pragma once
// The whole run seen from one rank of a split (exchange.hpp; docs/ARCHITECTURE.md, "Domain
// decomposition"): a rank's share of a whole state, the whole state gathered on rank 0 for the
// outputs, and the contact histories that travel with grains, keyed by global ids. Every call
// that takes a split state is collective: every rank makes it, in the same order. On a single
// process (no exchange) each is the plain thing and makes no call.
#include <functional>
#include <memory>
#include <vector>

#include "dem/state.hpp"

namespace dem {

GrainRecord grain_record(const State& state, std::size_t i);

// The local index of each of a state's grains (its first `count`) by global id: a sorted table,
// one allocation instead of a hash map's node per grain (at millions of grains the nodes
// fragmented the heap).
class IdIndex {
 public:
  IdIndex(const State& state, std::size_t count);
  // -1 where no grain has the id.
  std::int64_t find(std::int64_t id) const;

 private:
  std::vector<std::pair<std::int64_t, std::int64_t>> sorted_;
};
void append_grain(State& state, const GrainRecord& grain);
// Room for `grains` grains in every per-grain array, exactly, before appending arrivals or
// ghosts: appended one by one past the capacity, the arrays would double (a split run's memory
// per grain is what limits it: docs/ARCHITECTURE.md, "Domain decomposition").
void reserve_grains(State& state, std::size_t grains);

// A clump's body as it travels between ranks (a migration, the gathered state, a split
// checkpoint); its members travel as grains. A clump is never split: its members always live on
// the rank that owns its body, so that the body's force is summed from owned grains.
struct BodyRecord {
  Vec3 x, v, l, f, torque, inertia;
  double q[4];  // the orientation's coefficients x, y, z, w
  double mass, volume;
  std::int32_t members;
  std::uint8_t active;
  std::uint8_t unused[3];  // the padding, named, as GrainRecord's
};
// A member of a body, named by its global id, with its offset in the body's principal frame.
struct MemberRecord {
  std::int64_t id;
  Vec3 offset;
};
BodyRecord body_record(const Bodies& bodies, std::size_t b);
// Appends a body whose members, in template order, are the grains `member` already in `state`.
void append_body(State& state, const BodyRecord& body, const std::int32_t* member, const Vec3* offset);

// Keeps the grains listed in `keep`, in that order (their per-grain arrays), and the bodies
// whose members are all kept (a body is kept or dropped whole).
void keep_grains(State& state, const std::vector<std::size_t>& keep);

// Every rank's bodies on rank 0 (empty elsewhere), in the order of their first member's id:
// the order in which a single process created them. Collective.
struct BodiesImage {
  std::vector<BodyRecord> bodies;
  std::vector<MemberRecord> members;  // each body's, in body order
};
BodiesImage gathered_bodies(const State& state);
// Appends the image's bodies to a state that holds their members (found by id).
void append_bodies(State& state, const BodiesImage& image);

// Every pair history a state holds: use(i, j, history as owned grain i sees it) for each listed
// pair of i with a spring (j its partner's index, owned or a ghost), or, before the first list is
// built, for each of carried_pairs whose grain i is here (j = -1).
template <typename Use>
void for_each_history(const State& state, Use use);

// Per owned grain, the histories of its pairs as it sees them: from the neighbour list (a pair of
// two owned grains listed for both), or, before the first list is built, from carried_pairs.
std::vector<std::vector<CarriedPair>> contact_histories(const State& state);

// Appends `part`'s grains (with their forces) and clumps to `state`.
void append_grains(State& state, const State& part);

// Which grains of a state every rank holds alike (read from one file, drawn from one seed) this
// rank takes: every ranks-th unit (a free grain, or a clump with all its members), from its rank
// on; they migrate to their subdomains at the first build.
std::vector<std::size_t> share_indices(const State& whole, const Exchange& exchange);

// A rank's share of a state every rank holds whole (share_indices). No exchange: the whole state.
State share_of(State whole, std::shared_ptr<Exchange> exchange);

// Appends this rank's share of `fresh` (grains every rank drew alike) to a split state between
// two runs of the stepping loop: the ghosts are dropped and the lists' contact histories kept by
// id (carried_pairs) for the next initialize().
void add_share(State& state, const State& fresh);

// Rank 0 (or a single process) writes the outputs.
bool writes_outputs(const State& state);
// The owned grains of every rank in id order and their clumps' bodies (gathered_bodies), on rank
// 0 (empty elsewhere), with the time, the step and the grains lost; no lists or contacts.
State gathered(const State& state);
// Calls `use` with the whole state where the outputs are written: the state itself on a single
// process, the gathered one on rank 0 of a split. A failure there (a full disk) ends the call on
// every rank: rank 0 rethrows it, the others throw InputError.
void with_whole_state(const State& state, const std::function<void(const State&)>& use);
// Runs `work` where `here` says (writing a file on rank 0, reading one on every rank), then every
// rank learns whether it failed anywhere: the failed ones rethrow their error, the others throw
// InputError. Collective. No exchange: runs `work`, its error unchanged.
void run_and_agree(Exchange* exchange, bool here, const std::function<void()>& work);

template <typename Use>
void for_each_history(const State& s, Use use) {
  const std::size_t owned = s.owned();
  const NeighbourList& nl = s.neighbours;
  if (nl.row_start.size() != s.size() + 1) {
    const IdIndex index(s, owned);
    for (const CarriedPair& c : s.carried_pairs)
      if (const std::int64_t i = index.find(c.id); i >= 0) use(std::size_t(i), std::int64_t(-1), c);
    return;
  }
  for (std::size_t i = 0; i < owned; ++i)
    for (std::int32_t p = nl.row_start[i]; p < nl.row_start[i + 1]; ++p) {
      const Vec3f t = nl.tangential.empty() ? Vec3f::Zero() : nl.tangential[std::size_t(p)];
      const Vec3f r = nl.rolling.empty() ? Vec3f::Zero() : nl.rolling[std::size_t(p)];
      if (t.squaredNorm() == 0 && r.squaredNorm() == 0) continue;
      const std::size_t j = std::size_t(nl.partner[std::size_t(p)]);
      use(i, std::int64_t(j), CarriedPair{s.id[i], s.id[j], t, r});
    }
}

// The same pair as its other grain sees it.
inline CarriedPair other_view(const CarriedPair& c) { return {c.partner, c.id, -c.tangential, -c.rolling}; }

}  // namespace dem
