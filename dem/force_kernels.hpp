#pragma once
// The force kernels, as templates over a contact law (contact.hpp's ContactLaw of four slot
// laws), and RegisterContactLaw, which compiles them for one combination and enters it in the
// registry (contact_laws.hpp). Included by forces.cpp, which registers the built-in laws, and by
// the file of any other law: nowhere else (it holds the pair loop and its intrinsics).
#include <omp.h>
#if defined(__AVX512F__) && defined(__AVX512VL__) && defined(__AVX512BW__)
#include <immintrin.h>
#define DIEFILL_PAIR_TEST_AVX512 1
#endif

#include <algorithm>
#include <bit>
#include <string>
#include <utility>

#include "dem/contact.hpp"
#include "dem/contact_laws.hpp"
#include "dem/model.hpp"
#include "dem/state.hpp"
#include "dem/walls.hpp"

namespace dem {

namespace kernel {

// Contacts gathered from consecutive rows, as columns (one array per quantity), so that the
// law runs over them as a loop the compiler vectorises. The columns start on cache lines, so
// that the vector loads never straddle two, wherever the batch happens to lie; the whole batch
// (about 23 KB) fits a 32 KB first-level cache.
struct alignas(64) ContactBatch {
  static constexpr int capacity = 64;  // a multiple of 8: every column a whole number of lines
  int size = 0;
  alignas(64) std::int32_t pair[capacity], row[capacity], partner[capacity], slot[capacity];
  // in: separation x_i - x_j, radii, masses, velocities, history, pair parameters
  double dx[capacity], dy[capacity], dz[capacity], ri[capacity], rj[capacity], mi[capacity], mj[capacity];
  double vix[capacity], viy[capacity], viz[capacity], wix[capacity], wiy[capacity], wiz[capacity];
  double vjx[capacity], vjy[capacity], vjz[capacity], wjx[capacity], wjy[capacity], wjz[capacity];
  double tx[capacity], ty[capacity], tz[capacity], rx[capacity], ry[capacity], rz[capacity];  // in and out
  double e_star[capacity], damping[capacity], mu_s[capacity], mu_r[capacity], k_linear[capacity],
      kt_over_kn[capacity], sqrt_kt_over_kn[capacity], cohesion[capacity];
  // out: force on i, torques on i and on j, overlap over the smaller radius
  double fx[capacity], fy[capacity], fz[capacity];
  double tix[capacity], tiy[capacity], tiz[capacity], tjx[capacity], tjy[capacity], tjz[capacity];
  double overlap_rel[capacity];
};

// The law over a batch; each lane is one contact, computed exactly as alone. With one material
// for every grain (Common) the pairs' parameters are that pair's, not gathered: a compile-time
// choice, since a run-time one left the loop blending each parameter between a gathered column
// and a copy on the stack, and the stack loads ran at a third of the speed in two processes of
// three (the stack's placement decided; docs/PERFORMANCE.md, "How the kernel is built").
template <class Law, bool Common>
[[gnu::flatten]] void evaluate(ContactBatch& b, double dt, const PairParams& common) {
  for (int k = 0; k < b.size; ++k) {
    PairParams p = common;
    if constexpr (!Common) {
      p.e_star = b.e_star[k], p.damping = b.damping[k], p.mu_s = b.mu_s[k], p.mu_r = b.mu_r[k];
      p.k_linear = b.k_linear[k], p.kt_over_kn = b.kt_over_kn[k], p.sqrt_kt_over_kn = b.sqrt_kt_over_kn[k];
      p.cohesion = b.cohesion[k];
    }
    const Vec3 d(b.dx[k], b.dy[k], b.dz[k]);
    const double ri = b.ri[k], rj = b.rj[k], mi = b.mi[k], mj = b.mj[k];
    const double reach = ri + rj;
    const double dist = std::sqrt(d.squaredNorm());
    // One division for three quotients: 1/dist, R* = ri rj / reach and m* = mi mj / (mi + mj).
    const double inverse = 1.0 / (dist * reach * (mi + mj));
    ContactKinematics c;
    c.n = d * (inverse * reach * (mi + mj));
    c.overlap = reach - dist;
    c.r_eff = ri * rj * (inverse * dist * (mi + mj));
    c.m_eff = mi * mj * (inverse * dist * reach);
    const double arm_i = ri - 0.5 * c.overlap, arm_j = rj - 0.5 * c.overlap;
    const Vec3 wi(b.wix[k], b.wiy[k], b.wiz[k]), wj(b.wjx[k], b.wjy[k], b.wjz[k]);
    c.v_rel = Vec3(b.vix[k], b.viy[k], b.viz[k]) - wi.cross(arm_i * c.n) - (Vec3(b.vjx[k], b.vjy[k], b.vjz[k]) + wj.cross(arm_j * c.n));
    c.w_rel = wi - wj;
    ContactHistory h;
    if constexpr (Law::keeps_tangential) h.tangential = Vec3(b.tx[k], b.ty[k], b.tz[k]);
    if constexpr (Law::keeps_rolling) h.rolling = Vec3(b.rx[k], b.ry[k], b.rz[k]);
    const ContactForce cf = Law::eval(p, c, dt, h);
    // Contact point at -arm_i n from i and +arm_j n from j: torques -arm n x F on both.
    const Vec3 moment = c.n.cross(cf.force);
    const Vec3 ti = -arm_i * moment + cf.rolling_torque, tj = -arm_j * moment - cf.rolling_torque;
    b.fx[k] = cf.force.x(), b.fy[k] = cf.force.y(), b.fz[k] = cf.force.z();
    b.tix[k] = ti.x(), b.tiy[k] = ti.y(), b.tiz[k] = ti.z();
    b.tjx[k] = tj.x(), b.tjy[k] = tj.y(), b.tjz[k] = tj.z();
    if constexpr (Law::keeps_tangential) b.tx[k] = h.tangential.x(), b.ty[k] = h.tangential.y(), b.tz[k] = h.tangential.z();
    if constexpr (Law::keeps_rolling) b.rx[k] = h.rolling.x(), b.ry[k] = h.rolling.y(), b.rz[k] = h.rolling.z();
    b.overlap_rel[k] = c.overlap / std::min(ri, rj);
  }
}

// The part of n items (blocks) that `omp for schedule(static)` gives this thread: about the
// grains the other passes give it, so that they stay in its core's cache (dynamic chunks moved
// them between cores: 17 % slower on two threads).
inline std::pair<std::size_t, std::size_t> static_range(std::size_t n) {
  const std::size_t threads = std::size_t(omp_get_num_threads()), t = std::size_t(omp_get_thread_num());
  const std::size_t share = n / threads, extra = n % threads;
  const std::size_t begin = t * share + std::min(t, extra);
  return {begin, begin + share + (t < extra ? 1 : 0)};
}

// A batch's results added in row and pair order: to the row's grain, to its partner when in
// the same block (slot < 0), else to the cross pair's buffer; histories written back. The row's
// grain adds its contacts in a register, stored when the row changes: the same additions in the
// same order as through memory (a partner is always a later grain than its row). Returns the
// largest overlap over the smaller radius.
template <class Law>
double apply_batch(const ContactBatch& b, State& s) {
  NeighbourList& nl = s.neighbours;
  Vec3* const f = s.f.data();
  Vec3* const torque = s.torque.data();
  double max_overlap = 0;
  std::size_t row = std::size_t(b.row[0]);
  Vec3 row_force = f[row], row_torque = torque[row];
  for (int k = 0; k < b.size; ++k) {
    const std::size_t i = std::size_t(b.row[k]), p = std::size_t(b.pair[k]);
    if (i != row) {
      f[row] = row_force, torque[row] = row_torque;
      row = i, row_force = f[i], row_torque = torque[i];
    }
    const Vec3 force(b.fx[k], b.fy[k], b.fz[k]), partner_torque(b.tjx[k], b.tjy[k], b.tjz[k]);
    row_force += force;
    row_torque += Vec3(b.tix[k], b.tiy[k], b.tiz[k]);
    if (b.slot[k] < 0) {
      const std::size_t j = std::size_t(b.partner[k]);
      f[j] += -force;
      torque[j] += partner_torque;
    } else {
      s.cross_forces.force[std::size_t(b.slot[k])] = -force;
      s.cross_forces.torque[std::size_t(b.slot[k])] = partner_torque;
    }
    if constexpr (Law::keeps_tangential) nl.tangential[p] = Vec3(b.tx[k], b.ty[k], b.tz[k]).cast<float>();
    if constexpr (Law::keeps_rolling) nl.rolling[p] = Vec3(b.rx[k], b.ry[k], b.rz[k]).cast<float>();
    max_overlap = std::max(max_overlap, b.overlap_rel[k]);
  }
  f[row] = row_force, torque[row] = row_torque;
  return max_overlap;
}

// Up to eight consecutive listed pairs of one row tested for contact at once (lanes = how many):
// bit k of `touching` is set when pair k touches, of `cross` when its partner lies at or beyond
// `block_end` (the pair's share then goes through a buffer); the separations x_i - x_j and the
// partners' radii are kept for the contacts' batch. The test is the single pair's, operation for
// operation: not (d_x² + (d_y² + d_z²) >= (r_i + r_j)²), Eigen's order of the squared norm, so
// that the same pairs touch with or without the vector instructions, and a non-finite separation
// counts as a contact (the overlap check then stops the run). With AVX-512 the eight partners are
// gathered and compared in one pass: the scalar test, a load-compare-branch per listed pair, was
// the largest part of the pair stage (about half of the listed pairs are apart).
struct PairTest {
  std::uint32_t touching = 0, cross = 0;
  alignas(64) double dx[8], dy[8], dz[8], rj[8];
};

inline void test_pairs(PairTest& t, const Vec3& xi, double ri, const std::int32_t* partner, int lanes, const Vec3* x,
                       const double* radius, std::int32_t block_end) {
#ifdef DIEFILL_PAIR_TEST_AVX512
  const auto live = __mmask8((1u << lanes) - 1);
  const __m256i j = _mm256_maskz_loadu_epi32(live, partner);
  const __m512i j64 = _mm512_maskz_cvtepi32_epi64(live, j);  // maskz: the plain form warns of an undefined source (GCC 12)
  const __m512i coordinate = _mm512_add_epi64(j64, _mm512_add_epi64(j64, j64));  // x[j] is 3 doubles
  const double* const xd = x->data();
  const __m512d zero = _mm512_setzero_pd();
  const __m512d dx = _mm512_sub_pd(_mm512_set1_pd(xi.x()), _mm512_mask_i64gather_pd(zero, live, coordinate, xd, 8));
  const __m512d dy = _mm512_sub_pd(_mm512_set1_pd(xi.y()), _mm512_mask_i64gather_pd(zero, live, coordinate, xd + 1, 8));
  const __m512d dz = _mm512_sub_pd(_mm512_set1_pd(xi.z()), _mm512_mask_i64gather_pd(zero, live, coordinate, xd + 2, 8));
  const __m512d rj = _mm512_mask_i64gather_pd(zero, live, j64, radius, 8);
  const __m512d d2 = _mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_add_pd(_mm512_mul_pd(dy, dy), _mm512_mul_pd(dz, dz)));
  const __m512d reach = _mm512_add_pd(_mm512_set1_pd(ri), rj);
  t.touching = _mm512_mask_cmp_pd_mask(live, d2, _mm512_mul_pd(reach, reach), _CMP_NGE_UQ);
  t.cross = _mm256_mask_cmpge_epi32_mask(live, j, _mm256_set1_epi32(block_end));
  _mm512_store_pd(t.dx, dx), _mm512_store_pd(t.dy, dy), _mm512_store_pd(t.dz, dz), _mm512_store_pd(t.rj, rj);
#else
  t.touching = t.cross = 0;
  for (int k = 0; k < lanes; ++k) {
    const std::int32_t j = partner[k];
    const Vec3 d = xi - x[j];
    const double reach = ri + radius[j];
    t.dx[k] = d.x(), t.dy[k] = d.y(), t.dz[k] = d.z(), t.rj[k] = radius[j];
    t.touching |= std::uint32_t(!(d.squaredNorm() >= reach * reach)) << k;
    t.cross |= std::uint32_t(j >= block_end) << k;
  }
#endif
}

// The touching flags of `lanes` pairs from `flags`, as bits, and the new ones written.
inline std::uint32_t swap_touching(std::uint8_t* flags, int lanes, std::uint32_t now) {
#ifdef DIEFILL_PAIR_TEST_AVX512
  const auto live = __mmask16((1u << lanes) - 1);
  const __m128i old = _mm_maskz_loadu_epi8(live, flags);
  _mm_mask_storeu_epi8(flags, live, _mm_maskz_set1_epi8(__mmask16(now), 1));
  return _mm_test_epi8_mask(old, old);
#else
  std::uint32_t was = 0;
  for (int k = 0; k < lanes; ++k) was |= std::uint32_t(flags[k] != 0) << k, flags[k] = std::uint8_t(now >> k & 1u);
  return was;
#endif
}

// Blocks in parallel (state.hpp, NeighbourList): a thread takes whole blocks, sets their grains'
// forces to gravity, then goes through their rows in order, gathering the touching pairs into a
// batch, evaluating it, and adding the results in row and pair order (apply_batch). Every
// grain's force is thus gravity, the shares of lower rows of its block in row order, its own
// pairs in order, then (sum_forces) the cross shares in pair order: the same sums, bit for bit,
// whatever the thread count. The loop reads the grains through local pointers and keeps its
// counters in registers: a store per pair to the touching flags or to a counter in memory let
// the compiler assume any array pointer changed, and tied the loop to stack addresses.
template <class Law>
void pair_forces(const Model& model, State& s) {
  NeighbourList& nl = s.neighbours;
  const double dt = model.dt;
  double max_overlap = 0;
  std::int64_t contacts = 0;
  const PairParams* common = model.materials.size() == 1 ? &model.params(0, 0) : nullptr;
  // Rows of owned grains only: ghosts (after them) are partners, never rows (state.hpp).
  const std::size_t n = s.owned(), block = std::size_t(nl.block_size);
  const Vec3* const x = s.x.data();
  const Vec3* const v = s.v.data();
  const Vec3* const w = s.w.data();
  const double* const radius = s.radius.data();
  const double* const mass = s.mass.data();
  const std::int32_t* const partner = nl.partner.data();
  std::uint8_t* const touching = nl.touching.data();
#pragma omp parallel reduction(max : max_overlap) reduction(+ : contacts)
  {
    static thread_local ContactBatch batch;
    ContactBatch& b = batch;
    int count = 0;
    double largest = 0;
    std::int64_t evaluated = 0;
    const auto flush = [&] {
      b.size = count;
      if (common) evaluate<Law, true>(b, dt, *common);
      else evaluate<Law, false>(b, dt, PairParams{});
      if (count > 0) largest = std::max(largest, apply_batch<Law>(b, s));
      evaluated += count;
      count = 0;
    };
    const auto [first_block, last_block] = static_range(nl.blocks());
    for (std::size_t blk = first_block; blk < last_block; ++blk) {
      const std::size_t lo = blk * block, hi = std::min(n, lo + block);
      // A clump's weight acts at its centre of mass, which its members' centres need not share.
      for (std::size_t i = lo; i < hi; ++i) {
        s.f[i] = s.active[i] && s.body[i] < 0 ? Vec3(mass[i] * model.gravity) : Vec3::Zero();
        s.torque[i].setZero();
      }
      for (std::size_t i = lo; i < hi; ++i) {
        if (!s.active[i]) continue;  // an inactive grain has no listed pairs
        const Vec3 xi = x[i], vi = v[i], wi = w[i];
        const double ri = radius[i], mi = mass[i];
        const int mat_i = s.material[i];
        std::int32_t cross_slot = nl.cross_start[i];
        const std::int32_t row_end = nl.row_start[i + 1];
        for (std::int32_t first = nl.row_start[i]; first < row_end; first += 8) {
          const int lanes = std::min(8, row_end - first);
          PairTest t;
          test_pairs(t, xi, ri, partner + first, lanes, x, radius, std::int32_t(hi));
          // The cross slot of lane k: the row's next one plus the cross lanes before it.
          const auto slot_of = [&](int k) {
            return t.cross >> k & 1u ? cross_slot + std::popcount(t.cross & ((1u << k) - 1)) : -1;
          };
          // A contact that just ended clears its history and its share; most listed pairs were
          // apart already and cost only their flag.
          for (std::uint32_t ended = swap_touching(touching + first, lanes, t.touching) & ~t.touching; ended; ended &= ended - 1) {
            const int k = std::countr_zero(ended);
            const auto p = std::size_t(first + k);
            if constexpr (Law::keeps_tangential) nl.tangential[p].setZero();
            if constexpr (Law::keeps_rolling) nl.rolling[p].setZero();
            if (const std::int32_t slot = slot_of(k); slot >= 0)
              s.cross_forces.force[std::size_t(slot)].setZero(), s.cross_forces.torque[std::size_t(slot)].setZero();
          }
          for (std::uint32_t hits = t.touching; hits; hits &= hits - 1) {
            const int lane = std::countr_zero(hits);
            const std::int32_t p = first + lane;
            const auto j = std::size_t(partner[p]);
            if (count == ContactBatch::capacity) flush();
            const int k = count++;
            const Vec3 vj = v[j], wj = w[j];
            b.pair[k] = p, b.row[k] = std::int32_t(i), b.partner[k] = std::int32_t(j), b.slot[k] = slot_of(lane);
            b.dx[k] = t.dx[lane], b.dy[k] = t.dy[lane], b.dz[k] = t.dz[lane];
            b.ri[k] = ri, b.rj[k] = t.rj[lane], b.mi[k] = mi, b.mj[k] = mass[j];
            b.vix[k] = vi.x(), b.viy[k] = vi.y(), b.viz[k] = vi.z(), b.wix[k] = wi.x(), b.wiy[k] = wi.y(), b.wiz[k] = wi.z();
            b.vjx[k] = vj.x(), b.vjy[k] = vj.y(), b.vjz[k] = vj.z(), b.wjx[k] = wj.x(), b.wjy[k] = wj.y(), b.wjz[k] = wj.z();
            if constexpr (Law::keeps_tangential) {
              const Vec3f& h = nl.tangential[std::size_t(p)];
              b.tx[k] = h.x(), b.ty[k] = h.y(), b.tz[k] = h.z();
            }
            if constexpr (Law::keeps_rolling) {
              const Vec3f& h = nl.rolling[std::size_t(p)];
              b.rx[k] = h.x(), b.ry[k] = h.y(), b.rz[k] = h.z();
            }
            if (!common) {
              const PairParams& pp = model.params(mat_i, s.material[j]);
              b.e_star[k] = pp.e_star, b.damping[k] = pp.damping, b.mu_s[k] = pp.mu_s, b.mu_r[k] = pp.mu_r;
              b.k_linear[k] = pp.k_linear, b.kt_over_kn[k] = pp.kt_over_kn, b.sqrt_kt_over_kn[k] = pp.sqrt_kt_over_kn;
              b.cohesion[k] = pp.cohesion;
            }
          }
          cross_slot += std::popcount(t.cross);
        }
      }
      // A block's results are complete before the next block's grains are set to gravity.
      flush();
    }
    max_overlap = std::max(max_overlap, largest);
    contacts += evaluated;
  }
  s.counters.max_overlap_rel = max_overlap;
  s.counters.contacts = contacts;
}

inline constexpr std::size_t wall_prefetch_distance = 4;

template <class Law>
[[gnu::flatten]] void wall_forces(const Model& model, State& s) {
  const Array<std::int32_t>& near = s.neighbours.near_wall;
  const double dt = model.dt;
  double max_overlap = s.counters.max_overlap_rel;
  std::int64_t contacts = 0;
  // Only a moving wall does work (planes stand still): with none, every share is zero and the
  // serial sum below, a pass over every near-wall grain, is left out (the same 0 it would give).
  const bool walls_move = std::find(model.mesh_moves.begin(), model.mesh_moves.end(), 1) != model.mesh_moves.end();
  Array<double>& power = s.scratch_wall_power;
  power.assign(walls_move ? near.size() : 0, 0.0);
  const std::size_t walls = model.meshes.size();
  if (s.wall_candidates.size() != near.size() * walls) s.wall_candidates.assign(near.size() * walls, WallCandidates{});
#pragma omp parallel for schedule(static) reduction(max : max_overlap) reduction(+ : contacts)
  for (std::size_t q = 0; q < near.size(); ++q) {
    const std::size_t i = std::size_t(near[q]);
    // The faces a few grains ahead are fetched while this grain is queried: on a finely
    // tessellated wall each grain's faces are its own, and the query would wait on them.
    if (const std::size_t ahead = q + wall_prefetch_distance; walls && ahead < near.size())
      for (std::size_t m = 0; m < walls; ++m) {
        const WallCandidates& c = s.wall_candidates[ahead * walls + m];
        model.meshes[m].field->prefetch(c.triangles, &c.count);
      }
    if (!s.active[i]) continue;
    WallHit hits[wall_slots_per_particle];
    const int count = wall_hits(model, s.time, s.x[i], s.radius[i], hits, wall_slots_per_particle,
                                walls ? &s.wall_candidates[q * walls] : nullptr);
    WallSlot* slots = &s.wall_slots[q * wall_slots_per_particle];
    WallSlot next[wall_slots_per_particle];
    bool taken[wall_slots_per_particle] = {};
    for (int k = 0; k < count; ++k) {
      const WallHit& hit = hits[k];
      // Recognise last step's contact with the same wall by its normal (a grain rolling over
      // a tessellated face changes triangles, not contacts).
      int match = -1;
      double best = 0.7;
      for (int o = 0; o < wall_slots_per_particle; ++o)
        if (!taken[o] && slots[o].wall == hit.wall && slots[o].normal.dot(hit.normal) > best)
          best = slots[o].normal.dot(hit.normal), match = o;
      next[k].wall = hit.wall;
      next[k].normal = hit.normal;
      if (match >= 0) {
        taken[match] = true;
        next[k].history = slots[match].history;
      }
      ContactKinematics c;
      c.n = hit.normal;
      c.overlap = s.radius[i] - hit.distance;
      c.r_eff = s.radius[i];
      c.m_eff = s.mass[i];
      const double arm = std::max(0.0, hit.distance);
      c.v_rel = s.v[i] - s.w[i].cross(arm * c.n) - hit.wall_velocity;
      c.w_rel = s.w[i] - hit.wall_angular_velocity;
      const int wall_material = hit.wall < std::int32_t(model.planes.size())
                                    ? model.planes[std::size_t(hit.wall)].material
                                    : model.meshes[std::size_t(hit.wall) - model.planes.size()].material;
      const ContactForce cf = Law::eval(model.params(s.material[i], wall_material), c, dt, next[k].history);
      s.f[i] += cf.force;
      s.torque[i] += -arm * c.n.cross(cf.force) + cf.rolling_torque;
      if (walls_move) power[q] += cf.force.dot(hit.wall_velocity);
      if (c.overlap > max_overlap * s.radius[i]) max_overlap = c.overlap / s.radius[i];
      ++contacts;
    }
    for (int k = 0; k < wall_slots_per_particle; ++k)
      if (k < count) slots[k] = next[k];
      else if (slots[k].wall >= 0) slots[k] = WallSlot{};
  }
  double total_power = 0;
  for (double p : power) total_power += p;  // serial: the same sum for any thread count
  s.counters.wall_power = total_power;
  s.counters.max_overlap_rel = max_overlap;
  s.counters.wall_contacts = contacts;
}

}  // namespace kernel

// The registry's entry for one combination of slot laws, its kernels compiled here.
template <class Normal, class Tangential, class Rolling, class Cohesion>
CompiledContactLaw compiled_contact_law() {
  using Law = ContactLaw<Normal, Tangential, Rolling, Cohesion>;
  return {{std::string(Normal::name), std::string(Tangential::name), std::string(Rolling::name), std::string(Cohesion::name)},
          &kernel::pair_forces<Law>,
          &kernel::wall_forces<Law>,
          Law::keeps_tangential,
          Law::keeps_rolling,
          &Normal::collision_time,
          &Normal::energy,
          &Normal::unit_force,
          &Normal::unit_damping};
}

template <class Law>
SlotLaw slot_law(LawSlot slot) {
  return {slot, Law::name, Law::meaning, Law::reads, Law::keeps_history};
}

template <class Normal, class Tangential, class Rolling, class Cohesion>
std::array<SlotLaw, 4> slot_laws_of() {
  return {slot_law<Normal>(LawSlot::normal), slot_law<Tangential>(LawSlot::tangential), slot_law<Rolling>(LawSlot::rolling),
          slot_law<Cohesion>(LawSlot::cohesion)};
}

// A law of one's own: its slot's struct (as in contact.hpp) in a file of its own, and there, for
// each combination a scene may name,
//   const dem::RegisterContactLaw<dem::HertzNormal, dem::MindlinTangential, dem::NoRolling, MyCohesion> my_law;
// (docs/ARCHITECTURE.md, "Adding a contact law").
template <class Normal, class Tangential, class Rolling, class Cohesion>
struct RegisterContactLaw {
  RegisterContactLaw() {
    register_contact_law(compiled_contact_law<Normal, Tangential, Rolling, Cohesion>(),
                         slot_laws_of<Normal, Tangential, Rolling, Cohesion>());
  }
};

}  // namespace dem
