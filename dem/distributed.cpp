#include "dem/distributed.hpp"

#include <algorithm>
#include <cstring>
#include <numeric>
#include <unordered_map>

#include "core/error.hpp"

namespace dem {

GrainRecord grain_record(const State& s, std::size_t i) {
  GrainRecord g;
  std::memset(static_cast<void*>(&g), 0, sizeof g);  // padding too: the same state gives the same bytes
  g.id = s.id[i], g.x = s.x[i], g.v = s.v[i], g.w = s.w[i];
  g.radius = s.radius[i], g.mass = s.mass[i], g.inertia = s.inertia[i], g.material = s.material[i], g.active = s.active[i];
  return g;
}

void append_grain(State& s, const GrainRecord& g) {
  s.id.push_back(g.id), s.x.push_back(g.x), s.v.push_back(g.v), s.w.push_back(g.w);
  s.f.push_back(Vec3::Zero()), s.torque.push_back(Vec3::Zero());
  s.radius.push_back(g.radius), s.mass.push_back(g.mass), s.inertia.push_back(g.inertia);
  s.material.push_back(g.material), s.active.push_back(g.active), s.body.push_back(-1);
}

void keep_grains(State& s, const std::vector<std::size_t>& keep) {
  const auto select = [&](auto& a) {
    std::remove_reference_t<decltype(a)> kept;
    kept.reserve(keep.size());
    for (std::size_t i : keep) kept.push_back(a[i]);
    a.swap(kept);
  };
  select(s.id), select(s.x), select(s.v), select(s.w), select(s.f), select(s.torque);
  select(s.radius), select(s.mass), select(s.inertia), select(s.material), select(s.active), select(s.body);
}

std::vector<std::vector<CarriedPair>> contact_histories(const State& s) {
  const std::size_t owned = s.owned();
  std::vector<std::vector<CarriedPair>> pairs_of(owned);
  const NeighbourList& nl = s.neighbours;
  if (nl.row_start.size() != s.size() + 1) {
    std::unordered_map<std::int64_t, std::size_t> index;
    for (std::size_t i = 0; i < owned; ++i) index.emplace(s.id[i], i);
    for (const CarriedPair& c : s.carried_pairs)
      if (const auto at = index.find(c.id); at != index.end()) pairs_of[at->second].push_back(c);
    return pairs_of;
  }
  // A pair of two grains of this rank goes with both, as either may leave: a grain that took none
  // to a rank where its partner is a ghost would start the pair afresh there, while the partner's
  // rank kept the spring (the pair's two forces then differ, and momentum drifts).
  for (std::size_t i = 0; i < owned; ++i)
    for (std::int32_t p = nl.row_start[i]; p < nl.row_start[i + 1]; ++p) {
      const Vec3 t = nl.tangential.empty() ? Vec3::Zero() : nl.tangential[std::size_t(p)];
      const Vec3 r = nl.rolling.empty() ? Vec3::Zero() : nl.rolling[std::size_t(p)];
      if (t.squaredNorm() == 0 && r.squaredNorm() == 0) continue;
      const std::size_t j = std::size_t(nl.partner[std::size_t(p)]);
      pairs_of[i].push_back({s.id[i], s.id[j], t, r});
      if (j < owned) pairs_of[j].push_back({s.id[j], s.id[i], -t, -r});
    }
  return pairs_of;
}

std::vector<std::size_t> share_indices(std::size_t count, const Exchange& exchange) {
  std::vector<std::size_t> mine;
  for (std::size_t k = std::size_t(exchange.rank()); k < count; k += std::size_t(exchange.ranks())) mine.push_back(k);
  return mine;
}

State share_of(State whole, std::shared_ptr<Exchange> exchange) {
  if (!exchange) return whole;
  keep_grains(whole, share_indices(whole.size(), *exchange));
  whole.neighbours = {};
  whole.wall_slots.clear();
  whole.lost = exchange->rank() == 0 ? whole.lost : 0;  // counted once, summed over the ranks
  whole.exchange = std::move(exchange);
  return whole;
}

void add_share(State& s, const State& fresh) {
  std::vector<CarriedPair> carried;
  for (const auto& of_grain : contact_histories(s)) carried.insert(carried.end(), of_grain.begin(), of_grain.end());
  std::vector<std::size_t> owned(s.owned());
  std::iota(owned.begin(), owned.end(), std::size_t{0});
  keep_grains(s, owned);
  s.ghosts = 0;
  Array<std::int32_t> near_wall = std::move(s.neighbours.near_wall);  // the wall slots' grains: owned ones
  s.neighbours = {};
  s.neighbours.near_wall = std::move(near_wall);
  s.carried_pairs = std::move(carried);
  for (std::size_t k : share_indices(fresh.size(), *s.exchange)) append_grain(s, grain_record(fresh, k));
}

bool writes_outputs(const State& s) { return !s.exchange || s.exchange->rank() == 0; }

State gathered(const State& s) {
  State whole;
  whole.time = s.time, whole.step = s.step, whole.wall_work = s.wall_work;
  whole.lost = s.exchange ? s.exchange->sum(s.lost) : s.lost;
  std::vector<char> mine;
  for (std::size_t i = 0; i < s.owned(); ++i) put(mine, grain_record(s, i));
  const std::vector<char> all = s.exchange ? s.exchange->gather(mine) : mine;
  std::vector<GrainRecord> grains;
  for (const char* at = all.data(); at < all.data() + all.size();) grains.push_back(take<GrainRecord>(at));
  std::sort(grains.begin(), grains.end(), [](const GrainRecord& a, const GrainRecord& b) { return a.id < b.id; });
  for (const GrainRecord& g : grains) append_grain(whole, g);
  return whole;
}

void with_whole_state(const State& s, const std::function<void(const State&)>& use) {
  if (!s.exchange) return use(s);
  const State whole = gathered(s);
  std::exception_ptr failure;
  if (writes_outputs(s)) {
    try {
      use(whole);
    } catch (...) {
      failure = std::current_exception();
    }
  }
  agree_on_failure(*s.exchange, failure);
}

void agree_on_failure(Exchange& exchange, const std::exception_ptr& failure) {
  if (exchange.max(failure ? 1.0 : 0.0) == 0) return;
  if (failure) std::rethrow_exception(failure);
  throw diefill::InputError("", "", "another rank could not go on (it says why)", "See rank 0's message");
}

}  // namespace dem
