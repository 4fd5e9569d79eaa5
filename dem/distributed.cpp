#include "dem/distributed.hpp"

#include <algorithm>
#include <cstring>
#include <numeric>
#include <stdexcept>

#include "core/error.hpp"

namespace dem {

GrainRecord grain_record(const State& s, std::size_t i) {
  GrainRecord g;
  std::memset(static_cast<void*>(&g), 0, sizeof g);  // padding too: the same state gives the same bytes
  g.id = s.id[i], g.x = s.x[i], g.v = s.v[i], g.w = s.w[i];
  g.radius = s.radius[i], g.mass = s.mass[i], g.material = s.material[i], g.active = s.active[i];
  return g;
}

void append_grain(State& s, const GrainRecord& g) {
  s.id.push_back(g.id), s.x.push_back(g.x), s.v.push_back(g.v), s.w.push_back(g.w);
  s.f.push_back(Vec3::Zero()), s.torque.push_back(Vec3::Zero());
  s.radius.push_back(g.radius), s.mass.push_back(g.mass);
  s.material.push_back(g.material), s.active.push_back(g.active), s.body.push_back(-1);
}

IdIndex::IdIndex(const State& s, std::size_t count) : sorted_(count) {
  for (std::size_t i = 0; i < count; ++i) sorted_[i] = {s.id[i], std::int64_t(i)};
  std::sort(sorted_.begin(), sorted_.end());
}

std::int64_t IdIndex::find(std::int64_t id) const {
  const auto at = std::lower_bound(sorted_.begin(), sorted_.end(), std::pair{id, std::int64_t(-1)});
  return at != sorted_.end() && at->first == id ? at->second : -1;
}

void reserve_grains(State& s, std::size_t grains) {
  const auto room = [grains](auto&... arrays) { (arrays.reserve(grains), ...); };
  room(s.id, s.x, s.v, s.w, s.f, s.torque, s.radius, s.mass, s.material, s.active, s.body);
}

BodyRecord body_record(const Bodies& B, std::size_t b) {
  BodyRecord r;
  std::memset(static_cast<void*>(&r), 0, sizeof r);  // padding too: the same state gives the same bytes
  r.x = B.x[b], r.v = B.v[b], r.l = B.l[b], r.f = B.f[b], r.torque = B.torque[b], r.inertia = B.inertia[b];
  std::copy_n(B.q[b].coeffs().data(), 4, r.q);
  r.mass = B.mass[b], r.volume = B.volume[b];
  r.members = B.member_start[b + 1] - B.member_start[b];
  r.active = B.active[b];
  return r;
}

void append_body(State& s, const BodyRecord& r, const std::int32_t* member, const Vec3* offset) {
  Bodies& B = s.bodies;
  const auto b = std::int32_t(B.size());
  Quat q;
  std::copy_n(r.q, 4, q.coeffs().data());
  B.x.push_back(r.x), B.v.push_back(r.v), B.q.push_back(q), B.l.push_back(r.l);
  B.f.push_back(r.f), B.torque.push_back(r.torque), B.mass.push_back(r.mass), B.inertia.push_back(r.inertia);
  B.volume.push_back(r.volume), B.active.push_back(r.active);
  if (B.member_start.empty()) B.member_start.push_back(0);
  for (std::int32_t k = 0; k < r.members; ++k) {
    B.member.push_back(member[k]);
    B.offset.push_back(offset[k]);
    s.body[std::size_t(member[k])] = b;
  }
  B.member_start.push_back(std::int32_t(B.member.size()));
}

void keep_grains(State& s, const std::vector<std::size_t>& keep) {
  const auto select = [&](auto& a) {
    std::remove_reference_t<decltype(a)> kept;
    kept.reserve(keep.size());
    for (std::size_t i : keep) kept.push_back(a[i]);
    a.swap(kept);
  };
  const std::size_t before = s.size();
  select(s.id), select(s.x), select(s.v), select(s.w), select(s.f), select(s.torque);
  select(s.radius), select(s.mass), select(s.material), select(s.active), select(s.body);
  if (s.bodies.size() == 0) return;
  std::vector<std::int32_t> new_index(before, -1);
  for (std::size_t k = 0; k < keep.size(); ++k) new_index[keep[k]] = std::int32_t(k);
  const Bodies old = std::move(s.bodies);
  s.bodies = {};
  std::vector<std::int32_t> member;
  for (std::size_t b = 0; b < old.size(); ++b) {
    member.clear();
    for (std::int32_t k = old.member_start[b]; k < old.member_start[b + 1]; ++k)
      member.push_back(new_index[std::size_t(old.member[std::size_t(k)])]);
    const auto kept = std::count_if(member.begin(), member.end(), [](std::int32_t i) { return i >= 0; });
    if (kept == 0) continue;
    if (std::size_t(kept) != member.size()) throw std::logic_error("keep_grains: a clump's members kept in part");
    append_body(s, body_record(old, b), member.data(), &old.offset[std::size_t(old.member_start[b])]);
  }
}

BodiesImage gathered_bodies(const State& s) {
  const Bodies& B = s.bodies;
  std::vector<char> mine;
  for (std::size_t b = 0; b < B.size(); ++b) {
    put(mine, body_record(B, b));
    for (std::int32_t k = B.member_start[b]; k < B.member_start[b + 1]; ++k)
      put(mine, MemberRecord{s.id[std::size_t(B.member[std::size_t(k)])], B.offset[std::size_t(k)]});
  }
  const std::vector<char> all = s.exchange ? s.exchange->gather(mine) : mine;
  std::vector<std::pair<BodyRecord, std::vector<MemberRecord>>> bodies;
  for (const char* at = all.data(); at < all.data() + all.size();) {
    auto& [body, members] = bodies.emplace_back(take<BodyRecord>(at), std::vector<MemberRecord>{});
    for (std::int32_t k = 0; k < body.members; ++k) members.push_back(take<MemberRecord>(at));
  }
  std::sort(bodies.begin(), bodies.end(), [](const auto& a, const auto& b) { return a.second[0].id < b.second[0].id; });
  BodiesImage image;
  for (const auto& [body, members] : bodies) {
    image.bodies.push_back(body);
    image.members.insert(image.members.end(), members.begin(), members.end());
  }
  return image;
}

void append_bodies(State& s, const BodiesImage& image) {
  if (image.bodies.empty()) return;
  const IdIndex index(s, s.size());
  std::vector<std::int32_t> member;
  std::vector<Vec3> offset;
  std::size_t at = 0;
  for (const BodyRecord& body : image.bodies) {
    member.clear(), offset.clear();
    for (std::int32_t k = 0; k < body.members; ++k, ++at) {
      const std::int64_t i = index.find(image.members[at].id);
      if (i < 0) throw std::logic_error("append_bodies: a clump's member is not in the state");
      member.push_back(std::int32_t(i)), offset.push_back(image.members[at].offset);
    }
    append_body(s, body, member.data(), offset.data());
  }
}

std::vector<std::vector<CarriedPair>> contact_histories(const State& s) {
  const std::size_t owned = s.owned();
  std::vector<std::vector<CarriedPair>> pairs_of(owned);
  // A pair of two grains of this rank goes with both, as either may leave: a grain that took none
  // to a rank where its partner is a ghost would start the pair afresh there, while the partner's
  // rank kept the spring (the pair's two forces then differ, and momentum drifts).
  for_each_history(s, [&](std::size_t i, std::int64_t j, const CarriedPair& c) {
    pairs_of[i].push_back(c);
    if (j >= 0 && std::size_t(j) < owned) pairs_of[std::size_t(j)].push_back(other_view(c));
  });
  return pairs_of;
}

void append_grains(State& s, const State& part) {
  const auto first = std::int32_t(s.size());
  reserve_grains(s, s.size() + part.size());
  for (std::size_t i = 0; i < part.size(); ++i) {
    append_grain(s, grain_record(part, i));
    s.f.back() = part.f[i], s.torque.back() = part.torque[i];
  }
  const Bodies& B = part.bodies;
  std::vector<std::int32_t> member;
  for (std::size_t b = 0; b < B.size(); ++b) {
    member.clear();
    for (std::int32_t k = B.member_start[b]; k < B.member_start[b + 1]; ++k) member.push_back(first + B.member[std::size_t(k)]);
    append_body(s, body_record(B, b), member.data(), &B.offset[std::size_t(B.member_start[b])]);
  }
}

std::vector<std::size_t> share_indices(const State& whole, const Exchange& exchange) {
  const Bodies& B = whole.bodies;
  std::vector<std::size_t> mine;
  std::size_t unit = 0;
  for (std::size_t i = 0; i < whole.size(); ++i) {
    const std::int32_t b = whole.body[i];
    const std::size_t first = b < 0 ? i : std::size_t(B.member[std::size_t(B.member_start[std::size_t(b)])]);
    if (first != i) continue;  // a clump's other members go with its first
    if (unit++ % std::size_t(exchange.ranks()) != std::size_t(exchange.rank())) continue;
    if (b < 0) mine.push_back(i);
    else
      for (std::int32_t k = B.member_start[std::size_t(b)]; k < B.member_start[std::size_t(b) + 1]; ++k)
        mine.push_back(std::size_t(B.member[std::size_t(k)]));
  }
  return mine;
}

State share_of(State whole, std::shared_ptr<Exchange> exchange) {
  if (!exchange) return whole;
  keep_grains(whole, share_indices(whole, *exchange));
  whole.neighbours = {};
  whole.wall_slots.clear();
  // Counted once, summed over the ranks.
  whole.lost = exchange->rank() == 0 ? whole.lost : 0;
  whole.wall_work = exchange->rank() == 0 ? whole.wall_work : 0;
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
  State share = fresh;
  keep_grains(share, share_indices(fresh, *s.exchange));
  append_grains(s, share);
}

bool writes_outputs(const State& s) { return !s.exchange || s.exchange->rank() == 0; }

State gathered(const State& s) {
  State whole;
  whole.time = s.time, whole.step = s.step;
  whole.wall_work = s.exchange ? s.exchange->sum(s.wall_work) : s.wall_work;
  whole.lost = s.exchange ? s.exchange->sum(s.lost) : s.lost;
  std::vector<char> mine;
  for (std::size_t i = 0; i < s.owned(); ++i) put(mine, grain_record(s, i));
  const std::vector<char> all = s.exchange ? s.exchange->gather(mine) : mine;
  std::vector<GrainRecord> grains;
  for (const char* at = all.data(); at < all.data() + all.size();) grains.push_back(take<GrainRecord>(at));
  std::sort(grains.begin(), grains.end(), [](const GrainRecord& a, const GrainRecord& b) { return a.id < b.id; });
  for (const GrainRecord& g : grains) append_grain(whole, g);
  append_bodies(whole, gathered_bodies(s));
  return whole;
}

void with_whole_state(const State& s, const std::function<void(const State&)>& use) {
  if (!s.exchange) return use(s);
  const State whole = gathered(s);
  run_and_agree(s.exchange.get(), writes_outputs(s), [&] { use(whole); });
}

void run_and_agree(Exchange* exchange, bool here, const std::function<void()>& work) {
  if (!exchange) return work();
  std::exception_ptr failure;
  if (here) {
    try {
      work();
    } catch (...) {
      failure = std::current_exception();
    }
  }
  if (exchange->max(failure ? 1.0 : 0.0) == 0) return;
  if (failure) std::rethrow_exception(failure);
  throw diefill::InputError("", "", "another rank could not go on (it says why)", "See rank 0's message");
}

}  // namespace dem
