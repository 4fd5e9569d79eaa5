#include "dem/neighbours.hpp"

#include <omp.h>

#include <algorithm>
#include <limits>
#include <numeric>
#include <parallel/algorithm>

#include "dem/distributed.hpp"
#include "dem/walls.hpp"

namespace dem {

namespace {

struct CellGrid {
  Vec3 origin;
  double size;
  std::array<int, 3> dims;
  std::vector<std::int32_t> start;   // [cells+1]
  std::vector<std::int32_t> members; // particle indices sorted by cell, ascending within a cell

  int cell_coord(double x, int axis) const {
    return std::clamp(int((x - origin[axis]) / size), 0, dims[std::size_t(axis)] - 1);
  }
  std::size_t cell_of(const Vec3& p) const {
    return (std::size_t(cell_coord(p.x(), 0)) * std::size_t(dims[1]) + std::size_t(cell_coord(p.y(), 1))) *
               std::size_t(dims[2]) + std::size_t(cell_coord(p.z(), 2));
  }
};

// The grid spans the active grains (not the whole domain, which may be far larger), with cells
// no smaller than the interaction reach and no more cells than a few per grain.
CellGrid make_grid(const Model& model, const State& s) {
  CellGrid g;
  double lo_x = std::numeric_limits<double>::infinity(), lo_y = lo_x, lo_z = lo_x, hi_x = -lo_x, hi_y = -lo_x, hi_z = -lo_x;
  std::size_t active = 0;
#pragma omp parallel for schedule(static) reduction(min : lo_x, lo_y, lo_z) reduction(max : hi_x, hi_y, hi_z) reduction(+ : active)
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.active[i]) {
      const Vec3& x = s.x[i];
      lo_x = std::min(lo_x, x.x()), lo_y = std::min(lo_y, x.y()), lo_z = std::min(lo_z, x.z());
      hi_x = std::max(hi_x, x.x()), hi_y = std::max(hi_y, x.y()), hi_z = std::max(hi_z, x.z());
      ++active;
    }
  Vec3 lo(lo_x, lo_y, lo_z), hi(hi_x, hi_y, hi_z);
  if (active == 0) lo = hi = Vec3::Zero();
  g.origin = lo;
  g.size = model.cell_size;
  const Vec3 extent = hi - lo;
  while ((extent / g.size).array().floor().cwiseMax(1.0).prod() > 8.0 * double(std::max<std::size_t>(active, 1)) + 1000)
    g.size *= 1.25;
  for (int a = 0; a < 3; ++a) g.dims[std::size_t(a)] = std::max(1, int(extent[a] / g.size));
  const std::size_t cells = std::size_t(g.dims[0]) * std::size_t(g.dims[1]) * std::size_t(g.dims[2]);
  g.start.assign(cells + 1, 0);
  std::vector<std::size_t> cell(s.size());
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.active[i]) cell[i] = g.cell_of(s.x[i]);
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.active[i]) ++g.start[cell[i] + 1];
  for (std::size_t c = 0; c < cells; ++c) g.start[c + 1] += g.start[c];
  g.members.resize(std::size_t(g.start[cells]));
  std::vector<std::int32_t> fill(g.start.begin(), g.start.end() - 1);
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.active[i]) g.members[std::size_t(fill[cell[i]]++)] = std::int32_t(i);
  return g;
}

// The grid of the particles after sort_particles, from the one before it: the cells keep their
// grains (positions do not move), each member renamed. A cell's members stay ascending: its active
// owned grains share one Morton key, sorted by their old index, and its ghosts keep their order
// after every owned grain.
void rename_members(CellGrid& g, const std::vector<std::int32_t>& new_index) {
#pragma omp parallel for schedule(static)
  for (std::size_t m = 0; m < g.members.size(); ++m) g.members[m] = new_index[std::size_t(g.members[m])];
}

// Applies `order` (new index -> old index) to per-particle arrays of one element type: each is
// gathered into a scratch array and swapped with it, so that the arrays take turns with one
// scratch, freed when they are done: kept from one rebuild to the next (one per element type) it
// was 45 bytes per grain held between rebuilds, outside the state (issue 47's honest bytes per
// grain; docs/PERFORMANCE.md, "Memory").
template <typename Values, typename... More>
void permute(const std::vector<std::int32_t>& order, Values& first, More&... more) {
  Values scratch;
  scratch.reserve(order.size());  // exactly the size: the arrays take turns with it
  scratch.resize(order.size());
  for (Values* a : {&first, &more...}) {
    auto* const out = scratch.data();
    const auto* const in = a->data();
#pragma omp parallel for schedule(static)
    for (std::size_t n = 0; n < order.size(); ++n) out[n] = in[std::size_t(order[n])];
    a->swap(scratch);
  }
}

// Interleaves the bits of a cell's coordinates (Morton order): consecutive particles then fill
// compact regions of space, so that a block of them holds most of its grains' neighbours.
std::uint64_t morton(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  const auto spread = [](std::uint64_t v) {
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffull;
    v = (v | v << 16) & 0x1f0000ff0000ffull;
    v = (v | v << 8) & 0x100f00f00f00f00full;
    v = (v | v << 4) & 0x10c30c30c30c30c3ull;
    v = (v | v << 2) & 0x1249249249249249ull;
    return v;
  };
  return spread(x) << 2 | spread(y) << 1 | spread(z);
}

// Active owned particles along the Morton curve of their cells (ties in index order), lost ones
// after them in their old order, then the ghosts as they came. new_index: old index -> new.
std::vector<std::int32_t> sort_particles(State& s, const CellGrid& g, std::vector<std::int32_t>& new_index) {
  // Keys of the active owned grains in index order (a prefix count places each), then sorted in
  // parallel: the keys are unique (index as tie-break), so every sort gives the same order.
  std::vector<std::int32_t> slot(s.owned() + 1, 0);
  for (std::size_t i = 0; i < s.owned(); ++i) slot[i + 1] = slot[i] + (s.active[i] ? 1 : 0);
  std::vector<std::pair<std::uint64_t, std::int32_t>> keyed(std::size_t(slot[s.owned()]));
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < s.owned(); ++i)
    if (s.active[i])
      keyed[std::size_t(slot[i])] = {morton(std::uint32_t(g.cell_coord(s.x[i].x(), 0)), std::uint32_t(g.cell_coord(s.x[i].y(), 1)),
                                            std::uint32_t(g.cell_coord(s.x[i].z(), 2))),
                                     std::int32_t(i)};
  __gnu_parallel::sort(keyed.begin(), keyed.end());
  std::vector<std::int32_t> order;
  order.reserve(s.size());
  for (const auto& [key, i] : keyed) order.push_back(i);
  std::vector<std::pair<std::uint64_t, std::int32_t>>().swap(keyed);  // 16 bytes a grain, done with
  for (std::size_t i = 0; i < s.owned(); ++i)
    if (!s.active[i]) order.push_back(std::int32_t(i));
  for (std::size_t i = s.owned(); i < s.size(); ++i) order.push_back(std::int32_t(i));
  new_index.assign(s.size(), -1);
#pragma omp parallel for schedule(static)
  for (std::size_t n = 0; n < order.size(); ++n) new_index[std::size_t(order[n])] = std::int32_t(n);
  permute(order, s.x, s.v, s.w, s.f, s.torque);
  permute(order, s.radius, s.mass);
  permute(order, s.id);
  permute(order, s.material, s.body);
  permute(order, s.active);
  for (std::int32_t& i : s.bodies.member) i = new_index[std::size_t(i)];
  return order;
}

// Wall contact history follows its grains into the new near-wall list (a grain touching a wall
// is always near it).
void carry_wall_slots(State& s, const Array<std::int32_t>& old_near, const Array<WallSlot>& old_slots,
                      const std::vector<std::int32_t>& order) {
  const Array<std::int32_t>& near = s.neighbours.near_wall;
  s.wall_slots.assign(near.size() * wall_slots_per_particle, WallSlot{});
#pragma omp parallel for schedule(static)
  for (std::size_t q = 0; q < near.size(); ++q) {
    const std::int32_t old_i = order[std::size_t(near[q])];
    const auto at = std::lower_bound(old_near.begin(), old_near.end(), old_i);
    if (at == old_near.end() || *at != old_i) continue;
    const std::size_t old_q = std::size_t(at - old_near.begin());
    for (int k = 0; k < wall_slots_per_particle; ++k)
      s.wall_slots[q * wall_slots_per_particle + std::size_t(k)] = old_slots[old_q * wall_slots_per_particle + std::size_t(k)];
  }
}

struct OldPair {
  std::int32_t i, j;
  Vec3f tangential, rolling;
};

// Particles per block (state.hpp, NeighbourList): a function of their number only, so that the
// sums are the same for any thread count; small enough that two threads get a dozen blocks each
// for balance, large enough that most pairs lie within one.
std::int32_t block_size_for(std::size_t n) { return std::int32_t(std::clamp<std::size_t>(n / 32, 256, 4096)); }

// The cross pairs (partner in a later block): each row's buffer slots in pair order, and for each
// partner the slots naming it, ascending.
void index_cross_pairs(NeighbourList& nl, std::size_t n, std::size_t owned) {
  nl.block_size = block_size_for(owned);
  const std::size_t block = std::size_t(nl.block_size);
  nl.cross_start.assign(n + 1, 0);
  nl.cross_reverse_start.assign(n + 1, 0);
  // Blocks cover the owned grains; a ghost partner (after them) is always a cross pair.
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t block_end = std::min(owned, (i / block + 1) * block);
    std::int32_t cross = 0;
    for (std::int32_t p = nl.row_start[i]; p < nl.row_start[i + 1]; ++p)
      if (std::size_t(nl.partner[std::size_t(p)]) >= block_end) ++cross, ++nl.cross_reverse_start[std::size_t(nl.partner[std::size_t(p)]) + 1];
    nl.cross_start[i + 1] = nl.cross_start[i] + cross;
  }
  for (std::size_t i = 0; i < n; ++i) nl.cross_reverse_start[i + 1] += nl.cross_reverse_start[i];
  nl.cross_reverse.resize(std::size_t(nl.cross_start[n]));
  std::vector<std::int32_t> fill(nl.cross_reverse_start.begin(), nl.cross_reverse_start.end() - 1);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t block_end = std::min(owned, (i / block + 1) * block);
    std::int32_t slot = nl.cross_start[i];
    for (std::int32_t p = nl.row_start[i]; p < nl.row_start[i + 1]; ++p)
      if (const std::size_t j = std::size_t(nl.partner[std::size_t(p)]); j >= block_end) nl.cross_reverse[std::size_t(fill[j]++)] = slot++;
  }
}

// The old pairs' histories grouped by row, the smaller new index of the two (the history is
// its view: the other's is negated): row i's are [start[i], start[i+1]), each its partner and
// its springs (tangential only under a tangential law, rolling only under EPSD), kept as arrays
// apart (a third of the bytes of whole records at a rebuild of millions of grains). A counting
// sort in two passes over `visit`, which calls add(OldPair) for every pair, so that no list of
// them is held in between; each row keeps the order `visit` gives.
struct RowHistories {
  std::vector<std::int32_t> start, partner;
  Array<Vec3f> tangential, rolling;
};
template <typename Visit>
void histories_by_row(std::size_t n, bool tangential, bool rolling, Visit visit, RowHistories& h) {
  const auto smaller_first = [](OldPair o) {
    if (o.i > o.j) std::swap(o.i, o.j), o.tangential = -o.tangential, o.rolling = -o.rolling;
    return o;
  };
  h.start.assign(n + 1, 0);
  visit([&](const OldPair& o) { ++h.start[std::size_t(smaller_first(o).i) + 1]; });
  for (std::size_t i = 0; i < n; ++i) h.start[i + 1] += h.start[i];
  const auto total = std::size_t(h.start[n]);
  h.partner.resize(total);
  h.tangential.resize(tangential ? total : 0);
  h.rolling.resize(rolling ? total : 0);
  std::vector<std::int32_t> fill(h.start.begin(), h.start.end() - 1);
  visit([&](const OldPair& o) {
    const OldPair first = smaller_first(o);
    const auto k = std::size_t(fill[std::size_t(first.i)]++);
    h.partner[k] = first.j;
    if (tangential) h.tangential[k] = first.tangential;
    if (rolling) h.rolling[k] = first.rolling;
  });
}

// The histories of the list's pairs, by their particles' new indices: new_index[i] of the list's
// particle i, or after a migration new_index[renumbered[i]], skipping a pair of a grain that left.
template <typename Add>
void visit_listed_histories(const NeighbourList& nl, const std::vector<std::int32_t>& renumbered,
                            const std::vector<std::int32_t>& new_index, Add add) {
  const auto now = [&](std::size_t i) { return renumbered.empty() ? new_index[i] : renumbered[i] < 0 ? -1 : new_index[std::size_t(renumbered[i])]; };
  for (std::size_t i = 0; i + 1 < nl.row_start.size(); ++i)
    for (std::int32_t p = nl.row_start[i]; p < nl.row_start[i + 1]; ++p) {
      const Vec3f t = nl.tangential.empty() ? Vec3f::Zero() : nl.tangential[std::size_t(p)];
      const Vec3f r = nl.rolling.empty() ? Vec3f::Zero() : nl.rolling[std::size_t(p)];
      if (t.squaredNorm() == 0 && r.squaredNorm() == 0) continue;
      if (const std::int32_t a = now(i), b = now(std::size_t(nl.partner[std::size_t(p)])); a >= 0 && b >= 0) add(OldPair{a, b, t, r});
    }
}

// The histories that came with migrated grains (global ids), by their new local indices.
template <typename Add>
void visit_carried_histories(const State& s, const IdIndex& index, Add add) {
  for (const CarriedPair& c : s.carried_pairs)
    if (const std::int64_t i = index.find(c.id), j = index.find(c.partner); i >= 0 && j >= 0)
      add(OldPair{std::int32_t(i), std::int32_t(j), c.tangential, c.rolling});
}

// The old pairs' histories by the new indices, grouped by row in a counting sort (linear,
// stable: within a row the old list's order, the same every run; split over ranks, a pair that met
// across a subdomain face comes once from each side, the two views agreeing to rounding, and the
// first is taken). They come from the list or, split over ranks, with the grains, by global id
// (exchange.hpp); those carried ones are then done with.
RowHistories take_old_histories(State& s, const std::vector<std::int32_t>& new_index, bool tangential, bool rolling) {
  const NeighbourList& nl = s.neighbours;
  const std::size_t n = s.size();
  RowHistories old;
  if (s.exchange) {
    const IdIndex index(s, n);
    histories_by_row(n, tangential, rolling, [&](auto add) {
      if (!s.renumbered.empty()) visit_listed_histories(nl, s.renumbered, new_index, add);
      visit_carried_histories(s, index, add);
    }, old);
    std::vector<CarriedPair>().swap(s.carried_pairs);
    std::vector<std::int32_t>().swap(s.renumbered);
  } else {
    histories_by_row(n, tangential, rolling, [&](auto add) { visit_listed_histories(nl, {}, new_index, add); }, old);
  }
  return old;
}

// The new list's partners as the row scan finds them, in the chunks of consecutive rows the scan's
// dynamic schedule hands out, and every row's length. A chunk's rows, one after the other, take an
// array of their exact size: a vector per row cost half a million allocations per rebuild on 500k
// grains, and a growing buffer per thread kept up to half of itself spare, more on the thread the
// schedule gave more rows (10 bytes a grain at the rebuild's peak at 500k grains, two threads).
struct FoundRows {
  static constexpr std::size_t chunk = 256;  // rows
  std::vector<std::vector<std::int32_t>> by_chunk;  // [chunks]
  std::vector<std::int32_t> length;  // [N]
};

// Rows in parallel: every owned particle scans the 27 cells around it for j > i within reach
// (ghosts, after the owned ones, are partners only). The grid is taken, and freed on return,
// before the list's arrays fill at the rebuild's peak.
FoundRows scan_rows(const Model& model, const State& s, const CellGrid grid) {
  FoundRows rows;
  rows.by_chunk.resize((s.owned() + FoundRows::chunk - 1) / FoundRows::chunk);
  rows.length.assign(s.size(), 0);
#pragma omp parallel
  {
    std::vector<std::int32_t> buffer, apart;
#pragma omp for schedule(dynamic, 1)
    for (std::size_t chunk = 0; chunk < rows.by_chunk.size(); ++chunk) {
      buffer.clear();
      for (std::size_t i = chunk * FoundRows::chunk; i < std::min(s.owned(), (chunk + 1) * FoundRows::chunk); ++i) {
        if (!s.active[i]) continue;
        const Vec3& xi = s.x[i];
        const std::int32_t body = s.body[i];
        const int cx = grid.cell_coord(xi.x(), 0), cy = grid.cell_coord(xi.y(), 1), cz = grid.cell_coord(xi.z(), 2);
        const std::size_t begin = buffer.size();
        for (int a = std::max(0, cx - 1); a <= std::min(grid.dims[0] - 1, cx + 1); ++a)
          for (int b = std::max(0, cy - 1); b <= std::min(grid.dims[1] - 1, cy + 1); ++b)
            for (int c = std::max(0, cz - 1); c <= std::min(grid.dims[2] - 1, cz + 1); ++c) {
              const std::size_t cell = (std::size_t(a) * std::size_t(grid.dims[1]) + std::size_t(b)) * std::size_t(grid.dims[2]) + std::size_t(c);
              for (std::int32_t m = grid.start[cell]; m < grid.start[cell + 1]; ++m) {
                const std::int32_t j = grid.members[std::size_t(m)];
                // Members of one clump never touch: the clump is rigid.
                if (j <= std::int32_t(i) || (body >= 0 && s.body[std::size_t(j)] == body)) continue;
                const double reach = s.radius[i] + s.radius[std::size_t(j)] + model.skin;
                if ((s.x[std::size_t(j)] - xi).squaredNorm() < reach * reach) buffer.push_back(j);
              }
            }
        // Pairs touching now first, then the others, each part ascending: the force loop tests every
        // listed pair for contact, and contacts last thousands of steps, so the outcome runs in two
        // predictable stretches per row instead of at random (a mispredicted branch per pair cost
        // about a tenth of the force loop).
        // (In place, with the apart ones kept aside in the thread's own list: std::stable_partition
        // allocated a buffer per row.)
        const auto row = buffer.begin() + std::ptrdiff_t(begin);
        std::sort(row, buffer.end());
        auto kept = row;
        apart.clear();
        for (auto it = row; it != buffer.end(); ++it) {
          const double reach = s.radius[i] + s.radius[std::size_t(*it)];
          if ((s.x[std::size_t(*it)] - xi).squaredNorm() < reach * reach) *kept++ = *it;
          else apart.push_back(*it);
        }
        std::copy(apart.begin(), apart.end(), kept);
        rows.length[i] = std::int32_t(buffer.size() - begin);
      }
      rows.by_chunk[chunk].assign(buffer.begin(), buffer.end());
    }
  }
  return rows;
}

// Sizes a list array for the new build, in place when it has the room; otherwise it is freed before
// the new one is allocated (assign would hold both at once, at the rebuild's peak): its values were
// taken into the old histories already.
template <typename Values>
void refill(Values& a, std::size_t count, const typename Values::value_type& value) {
  if (count > a.capacity()) Values().swap(a);
  a.assign(count, value);
}

// The new list from the scan's rows, each pair with the history its two grains had, or none.
void fill_list(NeighbourList& nl, const FoundRows& rows, const RowHistories& old, bool tangential, bool rolling) {
  const std::size_t n = rows.length.size();
  nl.row_start.assign(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) nl.row_start[i + 1] = nl.row_start[i] + rows.length[i];
  const std::size_t pairs = std::size_t(nl.row_start[n]);
  refill(nl.partner, pairs, 0);
  refill(nl.tangential, tangential ? pairs : 0, Vec3f::Zero());
  refill(nl.rolling, rolling ? pairs : 0, Vec3f::Zero());
  refill(nl.touching, pairs, std::uint8_t(0));
#pragma omp parallel for schedule(static)
  for (std::size_t chunk = 0; chunk < rows.by_chunk.size(); ++chunk) {
    const std::int32_t* row = rows.by_chunk[chunk].data();
    for (std::size_t i = chunk * FoundRows::chunk; i < std::min(n, (chunk + 1) * FoundRows::chunk); row += rows.length[i++]) {
      const auto history_begin = old.partner.begin() + old.start[i], history_end = old.partner.begin() + old.start[i + 1];
      for (std::int32_t k = 0, p = nl.row_start[i]; k < rows.length[i]; ++k, ++p) {
        const std::int32_t j = row[k];
        nl.partner[std::size_t(p)] = j;
        // A grain has a dozen listed partners, a few with history: a scan beats a search.
        const auto history = std::find(history_begin, history_end, j);
        if (history != history_end) {
          const auto h = std::size_t(history - old.partner.begin());
          if (tangential) nl.tangential[std::size_t(p)] = old.tangential[h];
          if (rolling) nl.rolling[std::size_t(p)] = old.rolling[h];
          nl.touching[std::size_t(p)] = 1;
        }
      }
    }
  }
}

}  // namespace

bool needs_rebuild(const Model& model, const State& s, double largest_shift2) {
  const NeighbourList& nl = s.neighbours;
  // No list (a state read back or shared anew): every rank rebuilds, one holding no grain too.
  if (nl.x_at_build.size() != s.size() || nl.row_start.size() != s.size() + 1) return true;
  // How far any point of a wall has moved since the build: its origin's shift, plus for a
  // rotating wall the angle turned times its reach from the pivot (an arc bounds its chord).
  double wall_shift = 0;
  for (std::size_t m = 0; m < model.meshes.size(); ++m) {
    const Motion& motion = model.meshes[m].motion;
    const double turned = motion.angular_velocity.norm() * std::abs(s.time - nl.time_at_build) * model.mesh_reach[m];
    wall_shift = std::max(wall_shift, (motion.position(s.time) - nl.wall_shift_at_build[m]).norm() + turned);
  }
  return std::sqrt(largest_shift2) + model.build_position_rounding + wall_shift > 0.5 * model.skin;
}

void lose_outside_domain(const Model& model, State& s) {
  auto lose = [&s](std::size_t i) {
    s.active[i] = 0;
    s.v[i].setZero();
    s.w[i].setZero();
    ++s.lost;
  };
  for (std::size_t i = 0; i < s.owned(); ++i)
    if (s.active[i] && s.body[i] < 0 && !model.domain.contains(s.x[i])) lose(i);
  Bodies& bodies = s.bodies;
  for (std::size_t b = 0; b < bodies.size(); ++b)
    if (bodies.active[b] && !model.domain.contains(bodies.x[b])) {
      bodies.active[b] = 0;
      bodies.v[b].setZero();
      bodies.l[b].setZero();
      for (std::int32_t k = bodies.member_start[b]; k < bodies.member_start[b + 1]; ++k)
        lose(std::size_t(bodies.member[std::size_t(k)]));
    }
}

void rebuild_neighbours(const Model& model, State& s) {
  lose_outside_domain(model, s);

  NeighbourList& nl = s.neighbours;
  const bool tangential = model.contact_law->keeps_tangential, rolling = model.contact_law->keeps_rolling;
  const Array<std::int32_t> old_near = nl.near_wall;
  const Array<WallSlot> old_slots = std::move(s.wall_slots);
  std::vector<std::int32_t> new_index, order;
  {
    CellGrid grid = make_grid(model, s);
    order = sort_particles(s, grid, new_index);
    if (s.exchange) s.exchange->reordered(new_index);
    rename_members(grid, new_index);
    const RowHistories old = take_old_histories(s, new_index, tangential, rolling);
    const FoundRows rows = scan_rows(model, s, std::move(grid));
    fill_list(nl, rows, old, tangential, rolling);
  }  // the scratch is freed before the cross pairs are indexed
  const std::size_t n = s.size();
  index_cross_pairs(nl, n, s.owned());
  refill(s.cross_forces.force, nl.cross_reverse.size(), Vec3::Zero());
  refill(s.cross_forces.torque, nl.cross_reverse.size(), Vec3::Zero());

  nl.x_at_build.resize(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) nl.x_at_build[i] = s.x[i].cast<float>();
  nl.time_at_build = s.time;
  nl.wall_shift_at_build.resize(model.meshes.size());
  for (std::size_t m = 0; m < model.meshes.size(); ++m) nl.wall_shift_at_build[m] = model.meshes[m].motion.position(s.time);
  collect_near_wall(model, s);
  carry_wall_slots(s, old_near, old_slots, order);
  ++nl.builds;
}

}  // namespace dem
