#include "dem/forces.hpp"

#include <deque>
#include <vector>

#include "dem/force_kernels.hpp"

namespace dem {

namespace {

struct Registry {
  std::vector<SlotLaw> slots;
  std::deque<CompiledContactLaw> laws;  // a deque: a model's pointer stays valid as laws are added
};

void add(Registry& r, const CompiledContactLaw& law, const std::array<SlotLaw, 4>& slots) {
  for (const SlotLaw& slot : slots)
    if (std::none_of(r.slots.begin(), r.slots.end(), [&](const SlotLaw& o) { return o.slot == slot.slot && o.name == slot.name; }))
      r.slots.push_back(slot);
  r.laws.push_back(law);
}

// The built-in laws of each slot (contact.hpp), in the order `diefill scene --keys` lists them;
// every combination of them is compiled.
template <class... Laws>
struct LawList {};
using BuiltinNormal = LawList<HertzNormal, LinearNormal>;
using BuiltinTangential = LawList<MindlinTangential, NoTangential>;
using BuiltinRolling = LawList<EpsdRolling, CdtRolling, NoRolling>;
using BuiltinCohesion = LawList<SjkrCohesion, NoCohesion>;

template <class N, class T, class R, class... C>
void add_cohesions(Registry& r, LawList<C...>) {
  (add(r, compiled_contact_law<N, T, R, C>(), slot_laws_of<N, T, R, C>()), ...);
}
template <class N, class T, class... R, class Cohesions>
void add_rollings(Registry& r, LawList<R...>, Cohesions c) {
  (add_cohesions<N, T, R>(r, c), ...);
}
template <class N, class... T, class Rollings, class Cohesions>
void add_tangentials(Registry& r, LawList<T...>, Rollings rl, Cohesions c) {
  (add_rollings<N, T>(r, rl, c), ...);
}
template <class... N>
void add_every_combination(Registry& r, LawList<N...>) {
  (add_tangentials<N>(r, BuiltinTangential{}, BuiltinRolling{}, BuiltinCohesion{}), ...);
}

// The built-ins are entered when the registry is first used, so that a law registered by a static
// object of another file (RegisterContactLaw) always comes after them, whatever the order in which
// files are initialised.
Registry& registry() {
  static Registry r = [] {
    Registry built;
    add_every_combination(built, BuiltinNormal{});
    return built;
  }();
  return r;
}

}  // namespace

const std::vector<SlotLaw>& slot_laws() { return registry().slots; }

std::vector<std::string_view> slot_law_names(LawSlot slot) {
  std::vector<std::string_view> names;
  for (const SlotLaw& law : registry().slots)
    if (law.slot == slot) names.push_back(law.name);
  return names;
}

const CompiledContactLaw* find_contact_law(const ContactLawChoice& choice) {
  for (const CompiledContactLaw& law : registry().laws)
    if (law.choice.normal == choice.normal && law.choice.tangential == choice.tangential && law.choice.rolling == choice.rolling &&
        law.choice.cohesion == choice.cohesion)
      return &law;
  return nullptr;
}

void register_contact_law(const CompiledContactLaw& law, const std::array<SlotLaw, 4>& slots) { add(registry(), law, slots); }

void compute_pair_forces(const Model& model, State& state) { model.contact_law->pair_forces(model, state); }
void compute_wall_forces(const Model& model, State& state) { model.contact_law->wall_forces(model, state); }

void sum_forces(State& s, double kick_dt) {
  const NeighbourList& nl = s.neighbours;
  const CrossForces& cf = s.cross_forces;
  const std::size_t n = s.owned();
#pragma omp parallel for schedule(static)
  for (std::size_t j = 0; j < n; ++j) {
    if (!s.active[j]) continue;
    Vec3 f = s.f[j], t = s.torque[j];
    for (std::int32_t r = nl.cross_reverse_start[j]; r < nl.cross_reverse_start[j + 1]; ++r) {
      const std::size_t slot = std::size_t(nl.cross_reverse[std::size_t(r)]);
      f += cf.force[slot];
      t += cf.torque[slot];
    }
    s.f[j] = f;
    s.torque[j] = t;
    // Clump members move with their bodies, kicked once their members' forces are summed.
    if (kick_dt > 0 && s.body[j] < 0) {
      s.v[j] += (kick_dt / s.mass[j]) * f;
      s.w[j] += (kick_dt / sphere_inertia(s.mass[j], s.radius[j])) * t;
    }
  }
}

double elastic_energy(const Model& model, const State& s) {
  const auto energy = model.contact_law->elastic_energy;
  double total = 0;
  const NeighbourList& nl = s.neighbours;
  // A pair with a ghost is also counted by the ghost's owner: half here, half there.
  for (std::size_t i = 0; i < s.owned() && i + 1 < nl.row_start.size(); ++i)
    for (std::int32_t p = nl.row_start[i]; p < nl.row_start[i + 1]; ++p) {
      const std::size_t j = std::size_t(nl.partner[std::size_t(p)]);
      const double reach = s.radius[i] + s.radius[j];
      const double overlap = reach - (s.x[i] - s.x[j]).norm();
      if (overlap > 0 && s.active[i] && s.active[j])
        total += (j < s.owned() ? 1.0 : 0.5) *
                 energy(model.params(s.material[i], s.material[j]), s.radius[i] * s.radius[j] / reach, overlap);
    }
  // The wall queries start from copies of the grains' tracked seeds (the state stays as it is):
  // from the voxel corners they would walk over a voxel's worth of fine triangles each.
  const std::size_t walls = model.meshes.size();
  const bool tracked = walls > 0 && s.wall_candidates.size() == nl.near_wall.size() * walls;
  std::vector<WallCandidates> seeds(walls);
  for (std::size_t q = 0; q < nl.near_wall.size(); ++q) {
    const std::int32_t i = nl.near_wall[q];
    if (tracked) std::copy_n(&s.wall_candidates[q * walls], walls, seeds.begin());
    WallHit hits[wall_slots_per_particle];
    const int count = wall_hits(model, s.time, s.x[std::size_t(i)], s.radius[std::size_t(i)], hits, wall_slots_per_particle,
                                tracked ? seeds.data() : nullptr);
    for (int k = 0; k < count; ++k) {
      const int wm = hits[k].wall < std::int32_t(model.planes.size())
                         ? model.planes[std::size_t(hits[k].wall)].material
                         : model.meshes[std::size_t(hits[k].wall) - model.planes.size()].material;
      total += energy(model.params(s.material[std::size_t(i)], wm), s.radius[std::size_t(i)],
                      s.radius[std::size_t(i)] - hits[k].distance);
    }
  }
  return total;
}

}  // namespace dem
