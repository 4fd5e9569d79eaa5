#include "dem/checkpoint.hpp"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <unordered_map>
#include <unordered_set>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "dem/distributed.hpp"

namespace dem {

namespace {

constexpr char magic[8] = {'D', 'F', 'C', 'K', 'P', 'T', '0', '6'};
constexpr char split_magic[8] = {'D', 'F', 'C', 'K', 'S', 'P', '0', '3'};

struct Writer {
  std::string bytes;
  template <typename T>
  void value(const T& v) { bytes.append(reinterpret_cast<const char*>(&v), sizeof v); }
  template <typename T, typename A>
  void array(const std::vector<T, A>& v) {
    value(std::uint64_t(v.size()));
    bytes.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
};

struct Reader {
  std::ifstream in;
  template <typename T>
  void value(T& v) { in.read(reinterpret_cast<char*>(&v), sizeof v); }
  template <typename T, typename A>
  void array(std::vector<T, A>& v) {
    std::uint64_t n = 0;
    value(n);
    if (!in || n > (std::uint64_t(1) << 40) / sizeof(T)) {
      in.setstate(std::ios::failbit);
      return;
    }
    v.resize(n);
    in.read(reinterpret_cast<char*>(v.data()), std::streamsize(n * sizeof(T)));
  }
};

// One list of every field, used by both directions, so that they cannot drift apart.
template <typename IO, typename S>
void fields(IO& io, S& s) {
  io.array(s.id);
  io.array(s.x);
  io.array(s.v);
  io.array(s.w);
  io.array(s.f);
  io.array(s.torque);
  io.array(s.radius);
  io.array(s.mass);
  io.array(s.inertia);
  io.array(s.material);
  io.array(s.active);
  io.array(s.body);
  io.array(s.wall_slots);
  io.array(s.wall_candidates);  // where the wall queries start: a resumed run tracks on alike
  auto& b = s.bodies;
  io.array(b.x);
  io.array(b.v);
  io.array(b.q);
  io.array(b.l);
  io.array(b.f);
  io.array(b.torque);
  io.array(b.mass);
  io.array(b.inertia);
  io.array(b.volume);
  io.array(b.active);
  io.array(b.member_start);
  io.array(b.member);
  io.array(b.offset);
  auto& nl = s.neighbours;
  io.array(nl.row_start);
  io.array(nl.partner);
  io.array(nl.tangential);
  io.array(nl.rolling);
  io.array(nl.touching);
  io.value(nl.block_size);
  io.array(nl.cross_start);
  io.array(nl.cross_reverse_start);
  io.array(nl.cross_reverse);
  io.array(nl.near_wall);
  io.array(nl.x_at_build);
  io.array(nl.wall_shift_at_build);
  io.value(nl.time_at_build);
  io.value(nl.builds);
  io.value(s.time);
  io.value(s.step);
  io.value(s.lost);
  io.value(s.wall_work);
  io.value(s.energy_reference);
  io.value(s.energy_scale);
  io.value(s.energy_reference_set);
  io.value(s.loop_max_overlap_rel);
  io.value(s.loop_max_energy_gain);
}

// A run split over ranks, as one rank-count-free image: grains in id order with the forces of the
// last step (the next step's first half kick needs them), their wall contacts and pair histories
// keyed by global ids, and the clumps' bodies with their members' ids. Its lists are not kept: the first step after it builds them, and carries
// the histories into them by id.
struct CheckpointGrain {
  GrainRecord grain;
  Vec3 f, torque;
};
// A grain's wall slots, each laid out as a WallSlot with its padding named (as GrainRecord's).
struct SlotRecord {
  std::int64_t id;
  struct {
    std::int32_t wall, unused;
    Vec3 normal;
    ContactHistory history;
  } slot[wall_slots_per_particle];
};
static_assert(sizeof(SlotRecord) == sizeof(std::int64_t) + wall_slots_per_particle * sizeof(WallSlot));
struct SplitImage {
  double time = 0, wall_work = 0, energy_reference = 0, energy_scale = 0, loop_max_overlap_rel = 0, loop_max_energy_gain = 0;
  std::int64_t step = 0, lost = 0;
  std::uint8_t energy_reference_set = 0;
  std::vector<CheckpointGrain> grains;
  std::vector<SlotRecord> slots;
  std::vector<CarriedPair> pairs;
  BodiesImage bodies;
};

template <typename IO, typename I>
void split_fields(IO& io, I& image) {
  io.value(image.time);
  io.value(image.wall_work);
  io.value(image.energy_reference);
  io.value(image.energy_scale);
  io.value(image.step);
  io.value(image.lost);
  io.value(image.energy_reference_set);
  io.value(image.loop_max_overlap_rel);
  io.value(image.loop_max_energy_gain);
  io.array(image.grains);
  io.array(image.slots);
  io.array(image.pairs);
  io.array(image.bodies.bodies);
  io.array(image.bodies.members);
}

// The owned grains' share of the image, as bytes for rank 0.
void put_owned(const State& s, std::vector<char>& grains, std::vector<char>& slots, std::vector<char>& pairs) {
  for (std::size_t i = 0; i < s.owned(); ++i) {
    CheckpointGrain g;
    std::memset(static_cast<void*>(&g), 0, sizeof g);  // padding too: the same state, the same file
    g.grain = grain_record(s, i), g.f = s.f[i], g.torque = s.torque[i];
    put(grains, g);
  }
  const NeighbourList& nl = s.neighbours;
  if (s.wall_slots.size() == nl.near_wall.size() * wall_slots_per_particle)
    for (std::size_t q = 0; q < nl.near_wall.size(); ++q) {
      SlotRecord r;
      std::memset(static_cast<void*>(&r), 0, sizeof r);
      r.id = s.id[std::size_t(nl.near_wall[q])];
      for (int k = 0; k < wall_slots_per_particle; ++k) {
        const WallSlot& slot = s.wall_slots[q * wall_slots_per_particle + std::size_t(k)];
        r.slot[k].wall = slot.wall, r.slot[k].normal = slot.normal, r.slot[k].history = slot.history;
      }
      put(slots, r);
    }
  for (const auto& of_grain : contact_histories(s))
    for (const CarriedPair& c : of_grain) put(pairs, c);
}

template <typename T>
std::vector<T> records(const std::vector<char>& bytes) {
  std::vector<T> out;
  out.reserve(bytes.size() / sizeof(T));
  for (const char* at = bytes.data(); at < bytes.data() + bytes.size();) out.push_back(take<T>(at));
  return out;
}

// Collective on a split state; the image is complete on rank 0 (or a single process) only.
SplitImage image_of(const State& s) {
  SplitImage image;
  image.time = s.time, image.wall_work = s.wall_work, image.step = s.step;
  image.energy_reference = s.energy_reference, image.energy_scale = s.energy_scale;
  image.energy_reference_set = s.energy_reference_set;
  image.loop_max_overlap_rel = s.loop_max_overlap_rel, image.loop_max_energy_gain = s.loop_max_energy_gain;  // global on every rank
  image.lost = s.exchange ? s.exchange->sum(s.lost) : s.lost;
  std::vector<char> grains, slots, pairs;
  put_owned(s, grains, slots, pairs);
  if (s.exchange) grains = s.exchange->gather(grains), slots = s.exchange->gather(slots), pairs = s.exchange->gather(pairs);
  image.grains = records<CheckpointGrain>(grains);
  image.slots = records<SlotRecord>(slots);
  image.pairs = records<CarriedPair>(pairs);
  image.bodies = gathered_bodies(s);
  // In id order, so that the file is the same whichever rank held which grain.
  std::sort(image.grains.begin(), image.grains.end(), [](const auto& a, const auto& b) { return a.grain.id < b.grain.id; });
  std::sort(image.slots.begin(), image.slots.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
  std::sort(image.pairs.begin(), image.pairs.end(),
            [](const auto& a, const auto& b) { return a.id != b.id ? a.id < b.id : a.partner < b.partner; });
  return image;
}

// This rank's share of the image (share_indices, as share_of), ready to step.
State share_of_image(const SplitImage& image, std::shared_ptr<Exchange> exchange) {
  State s;
  for (const CheckpointGrain& g : image.grains) {
    append_grain(s, g.grain);
    s.f.back() = g.f, s.torque.back() = g.torque;
  }
  append_bodies(s, image.bodies);
  keep_grains(s, share_indices(s, *exchange));
  std::unordered_map<std::int64_t, std::size_t> index;
  for (std::size_t i = 0; i < s.size(); ++i) index.emplace(s.id[i], i);
  for (const SlotRecord& r : image.slots)
    if (const auto at = index.find(r.id); at != index.end()) {
      s.neighbours.near_wall.push_back(std::int32_t(at->second));
      for (const auto& slot : r.slot) s.wall_slots.push_back({slot.wall, slot.normal, slot.history});
    }
  for (const CarriedPair& c : image.pairs)
    if (index.count(c.id)) s.carried_pairs.push_back(c);
  s.time = image.time, s.step = image.step, s.wall_work = image.wall_work;
  s.lost = exchange->rank() == 0 ? image.lost : 0;
  s.energy_reference = image.energy_reference, s.energy_scale = image.energy_scale;
  s.energy_reference_set = image.energy_reference_set != 0;
  s.loop_max_overlap_rel = image.loop_max_overlap_rel, s.loop_max_energy_gain = image.loop_max_energy_gain;
  s.exchange = std::move(exchange);
  return s;
}

// Every clump names members that the image holds, at least one each.
bool bodies_match_grains(const SplitImage& image) {
  std::unordered_set<std::int64_t> ids;
  for (const CheckpointGrain& g : image.grains) ids.insert(g.grain.id);
  std::size_t members = 0;
  for (const BodyRecord& b : image.bodies.bodies) {
    if (b.members <= 0) return false;
    members += std::size_t(b.members);
  }
  if (members != image.bodies.members.size()) return false;
  return std::all_of(image.bodies.members.begin(), image.bodies.members.end(), [&](const MemberRecord& m) { return ids.count(m.id) > 0; });
}

std::string read_head(Reader& r, const Model& model, const std::filesystem::path& path) {
  char head[sizeof magic];
  std::string hash(model.hash.size(), '\0');
  r.in.read(head, sizeof head);
  r.in.read(hash.data(), std::streamsize(hash.size()));
  const std::string kind(head, sizeof head);
  if (r.in && kind != std::string(magic, sizeof magic) && kind != std::string(split_magic, sizeof split_magic) &&
      (kind.starts_with("DFCKPT") || kind.starts_with("DFCKSP")))
    throw diefill::InputError(path.string(), "", "the checkpoint was written by another version of diefill",
                              "Start afresh (without --resume)");
  if (!r.in || (kind != std::string(magic, sizeof magic) && kind != std::string(split_magic, sizeof split_magic)))
    throw diefill::InputError(path.string(), "", "not a diefill checkpoint", "Name a checkpoint file diefill wrote");
  if (hash != model.hash)
    throw diefill::InputError(path.string(), "model", "the checkpoint was written by a different scene or build",
                              "Resume with the scene that wrote it, or start afresh");
  return kind;
}

// The file read on this rank: the whole state of a single-process checkpoint, or (with an
// exchange) this rank's share of either kind.
State read_whole_or_split(const Model& model, const std::filesystem::path& path, std::shared_ptr<Exchange> exchange) {
  Reader r{std::ifstream(path, std::ios::binary)};
  const bool split = read_head(r, model, path) == std::string(split_magic, sizeof split_magic);
  if (split && !exchange)
    throw diefill::InputError(path.string(), "", "the checkpoint was written by a run split over MPI ranks",
                              "Resume it under mpirun, on any number of ranks (`mpirun -np 1` too)");
  State s;
  SplitImage image;
  if (split) split_fields(r, image);
  else fields(r, s);
  if (!r.in) throw diefill::InputError(path.string(), "", "the checkpoint is truncated", "Start afresh");
  if (split && !bodies_match_grains(image))
    throw diefill::InputError(path.string(), "", "the checkpoint's clumps name grains it does not hold (a damaged file)", "Start afresh");
  if (exchange) return share_of_image(split ? image : image_of(s), std::move(exchange));
  // The cross pairs' force buffers are scratch, refilled by the next force stage.
  s.cross_forces.force.assign(s.neighbours.cross_reverse.size(), Vec3::Zero());
  s.cross_forces.torque.assign(s.neighbours.cross_reverse.size(), Vec3::Zero());
  return s;
}

}  // namespace

void write_checkpoint(const Model& model, const State& state, const std::filesystem::path& path) {
  Writer w;
  if (!state.exchange) {
    w.bytes.append(magic, sizeof magic);
    w.bytes.append(model.hash);
    fields(w, state);
    diefill::write_file_atomic(path, w.bytes);
    return;
  }
  SplitImage image = image_of(state);
  run_and_agree(state.exchange.get(), writes_outputs(state), [&] {
    w.bytes.append(split_magic, sizeof split_magic);
    w.bytes.append(model.hash);
    split_fields(w, image);
    diefill::write_file_atomic(path, w.bytes);
  });
}

State read_checkpoint(const Model& model, const std::filesystem::path& path, std::shared_ptr<Exchange> exchange) {
  // Every rank reads the file; should one fail, all stop.
  State s;
  run_and_agree(exchange.get(), true, [&] { s = read_whole_or_split(model, path, exchange); });
  return s;
}

}  // namespace dem
