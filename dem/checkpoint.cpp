#include "dem/checkpoint.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <numeric>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "dem/distributed.hpp"

namespace dem {

namespace {

namespace fs = std::filesystem;

constexpr char magic[8] = {'D', 'F', 'C', 'K', 'P', 'T', '1', '0'};
constexpr char split_magic[8] = {'D', 'F', 'C', 'K', 'S', 'P', '0', '4'};
constexpr char piece_magic[8] = {'D', 'F', 'C', 'K', 'P', 'C', '0', '7'};

// Streams straight into the file: a rank's piece of ten million grains is never held twice.
struct Writer {
  std::ofstream out;
  template <typename T>
  void value(const T& v) { out.write(reinterpret_cast<const char*>(&v), sizeof v); }
  template <typename T, typename A>
  void array(const std::vector<T, A>& v) {
    value(std::uint64_t(v.size()));
    out.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof(T)));
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
  // The checks the next step makes of this one (dem/step.cpp), and a split rank's ghosts.
  io.value(s.counters.max_overlap_rel);
  io.value(s.counters.wall_power);
  io.value(s.counters.energy_gain);
  io.value(s.counters.checked_overlap_rel);
  io.value(s.counters.contacts);
  io.value(s.counters.wall_contacts);
  io.value(s.ghosts);
  io.array(s.carried_pairs);
}

// A split run's checkpoint (docs/ARCHITECTURE.md, "Domain decomposition"): every rank writes its
// own piece, `PATH.rank-R-of-N`, which is the rank's whole state (owned grains, ghosts, lists with
// their histories, wall contacts, counters) as a single process writes it, and what its exchange
// knows; rank 0 writes the index, PATH, last. The same rank count resumes each piece on its rank
// and goes on bit for bit; another count shares the pieces out and takes their owned grains with
// their histories keyed by global ids (the first step builds the lists and the subdomains anew).
struct SplitIndex {
  std::uint64_t ranks = 0;
  std::int64_t step = 0, lost = 0;
  double time = 0, wall_work = 0, energy_reference = 0, energy_scale = 0, loop_max_overlap_rel = 0, loop_max_energy_gain = 0;
  std::uint8_t energy_reference_set = 0;
};

template <typename IO, typename I>
void index_fields(IO& io, I& index) {
  io.value(index.ranks);
  io.value(index.step);
  io.value(index.lost);
  io.value(index.time);
  io.value(index.wall_work);
  io.value(index.energy_reference);
  io.value(index.energy_scale);
  io.value(index.loop_max_overlap_rel);
  io.value(index.loop_max_energy_gain);
  io.value(index.energy_reference_set);
}

fs::path piece_path(const fs::path& index, std::uint64_t rank, std::uint64_t ranks) {
  return fs::path(index).concat(fmt::format(".rank-{}-of-{}", rank, ranks));
}

void write_head(Writer& w, const char (&kind)[8], const Model& model) {
  w.out.write(kind, sizeof kind);
  w.out.write(model.hash.data(), std::streamsize(model.hash.size()));
}

// Writes through a temporary sibling, renamed into place when complete.
void write_atomically(const fs::path& path, const std::function<void(Writer&)>& write) {
  diefill::PendingFile pending(path);
  {
    Writer w{std::ofstream(pending.path(), std::ios::binary)};
    write(w);
    if (!w.out) throw diefill::InputError(path.string(), "", "cannot be written", "Check that the folder is writable and the disk is not full");
  }
  pending.commit();
}

void check_head(Reader& r, const char (&kind)[8], const Model& model, const fs::path& path) {
  char head[sizeof magic];
  std::string hash(model.hash.size(), '\0');
  r.in.read(head, sizeof head);
  r.in.read(hash.data(), std::streamsize(hash.size()));
  const std::string found(head, sizeof head), wanted(kind, sizeof kind);
  if (r.in && found != wanted && found.starts_with("DFCK"))
    throw diefill::InputError(path.string(), "", "the checkpoint was written by another version of diefill",
                              "Start afresh (without --resume)");
  if (!r.in || found != wanted) throw diefill::InputError(path.string(), "", "not a diefill checkpoint", "Name a checkpoint file diefill wrote");
  if (hash != model.hash)
    throw diefill::InputError(path.string(), "model", "the checkpoint was written by a different scene or build",
                              "Resume with the scene that wrote it, or start afresh");
}

// Whether the file is a split run's index (else a single process's checkpoint, or an error).
bool is_split(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  char head[sizeof magic] = {};
  in.read(head, sizeof head);
  return in && std::memcmp(head, split_magic, sizeof head) == 0;
}

// A piece's (or a single process's) state and what its exchange saved.
struct Piece {
  State state;
  std::vector<char> exchange;
};

Piece read_piece(const Model& model, const fs::path& path, const SplitIndex* index, std::uint64_t rank) {
  Reader r{std::ifstream(path, std::ios::binary)};
  if (!r.in)
    throw diefill::InputError(path.string(), "", "cannot be read (a piece of the split checkpoint is missing)",
                              "Keep every PATH.rank-R-of-N file beside the checkpoint, or start afresh");
  check_head(r, index ? piece_magic : magic, model, path);
  Piece piece;
  std::uint64_t written_rank = rank, written_ranks = index ? index->ranks : 1;
  std::int64_t step = 0;
  if (index) r.value(written_rank), r.value(written_ranks), r.value(step);
  fields(r, piece.state);
  if (index) r.array(piece.exchange);
  if (!r.in) throw diefill::InputError(path.string(), "", "the checkpoint is truncated", "Start afresh");
  if (index && (written_rank != rank || written_ranks != index->ranks || step != index->step))
    throw diefill::InputError(path.string(), "", "the piece belongs to another checkpoint than its index (a run ended while writing it)",
                              "Start afresh");
  // The cross pairs' force buffers are scratch, refilled by the next force stage.
  piece.state.cross_forces.force.assign(piece.state.neighbours.cross_reverse.size(), Vec3::Zero());
  piece.state.cross_forces.torque.assign(piece.state.neighbours.cross_reverse.size(), Vec3::Zero());
  return piece;
}

// Appends a piece's owned grains to `s`, with their forces, clumps, wall contacts and pair
// histories (by global id, for the next build); its ghosts and lists are left behind.
void append_owned(State& s, State piece) {
  std::vector<CarriedPair> pairs;
  for (const auto& of_grain : contact_histories(piece)) pairs.insert(pairs.end(), of_grain.begin(), of_grain.end());
  const NeighbourList& nl = piece.neighbours;
  const auto first = std::int32_t(s.size());
  if (piece.wall_slots.size() == nl.near_wall.size() * wall_slots_per_particle)
    for (std::size_t q = 0; q < nl.near_wall.size(); ++q) {
      s.neighbours.near_wall.push_back(first + nl.near_wall[q]);
      s.wall_slots.insert(s.wall_slots.end(), piece.wall_slots.begin() + std::ptrdiff_t(q * wall_slots_per_particle),
                          piece.wall_slots.begin() + std::ptrdiff_t((q + 1) * wall_slots_per_particle));
    }
  std::vector<std::size_t> owned(piece.owned());
  std::iota(owned.begin(), owned.end(), std::size_t{0});
  keep_grains(piece, owned);
  append_grains(s, piece);
  s.carried_pairs.insert(s.carried_pairs.end(), pairs.begin(), pairs.end());
  s.counters.max_overlap_rel = std::max(s.counters.max_overlap_rel, piece.counters.max_overlap_rel);
  s.counters.checked_overlap_rel = std::max(s.counters.checked_overlap_rel, piece.counters.checked_overlap_rel);
}

// This rank's state from `pieces` pieces written by as many ranks (1: a single process's file):
// on the same rank count its own piece as it was; on another, every ranks-th piece's owned grains
// from its rank on, the run's totals (grains lost, the walls' work) on rank 0.
State restore_split(const Model& model, const fs::path& path, const SplitIndex* index, std::shared_ptr<Exchange> exchange) {
  const auto rank = std::uint64_t(exchange->rank()), ranks = std::uint64_t(exchange->ranks());
  const std::uint64_t pieces = index ? index->ranks : 1;
  const auto piece_file = [&](std::uint64_t p) { return index ? piece_path(path, p, pieces) : path; };
  if (pieces == ranks && index) {
    Piece own = read_piece(model, piece_file(rank), index, rank);
    exchange->restore(own.exchange.data(), own.exchange.size());
    own.state.exchange = std::move(exchange);
    return std::move(own.state);
  }
  State s;
  s.neighbours.near_wall.clear();
  bool scalars = false;
  for (std::uint64_t p = rank; p < pieces; p += ranks) {
    Piece piece = read_piece(model, piece_file(p), index, p);
    if (!scalars) {
      s.time = piece.state.time, s.step = piece.state.step;
      s.energy_reference = piece.state.energy_reference, s.energy_scale = piece.state.energy_scale;
      s.energy_reference_set = piece.state.energy_reference_set;
      s.loop_max_overlap_rel = piece.state.loop_max_overlap_rel, s.loop_max_energy_gain = piece.state.loop_max_energy_gain;
      scalars = true;
    }
    s.lost += piece.state.lost, s.wall_work += piece.state.wall_work;
    append_owned(s, std::move(piece.state));
  }
  if (index) {
    s.time = index->time, s.step = index->step;
    s.energy_reference = index->energy_reference, s.energy_scale = index->energy_scale;
    s.energy_reference_set = index->energy_reference_set != 0;
    s.loop_max_overlap_rel = index->loop_max_overlap_rel, s.loop_max_energy_gain = index->loop_max_energy_gain;
    s.lost = rank == 0 ? index->lost : 0;
    s.wall_work = rank == 0 ? index->wall_work : 0;
  }
  s.exchange = std::move(exchange);
  return s;
}

State read_any(const Model& model, const fs::path& path, std::shared_ptr<Exchange> exchange) {
  if (!is_split(path)) {
    if (!exchange) return std::move(read_piece(model, path, nullptr, 0).state);
    return restore_split(model, path, nullptr, std::move(exchange));
  }
  if (!exchange)
    throw diefill::InputError(path.string(), "", "the checkpoint was written by a run split over MPI ranks",
                              "Resume it under mpirun, on any number of ranks (`mpirun -np 1` too)");
  Reader r{std::ifstream(path, std::ios::binary)};
  check_head(r, split_magic, model, path);
  SplitIndex index;
  index_fields(r, index);
  if (!r.in || index.ranks == 0) throw diefill::InputError(path.string(), "", "the checkpoint is truncated", "Start afresh");
  return restore_split(model, path, &index, std::move(exchange));
}

// Removes the pieces that checkpoints at this path wrote for another rank count (0: for any).
void remove_pieces(const fs::path& path, std::uint64_t but_of_ranks) {
  const std::string prefix = path.filename().string() + ".rank-", own = fmt::format("-of-{}", but_of_ranks);
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(path.parent_path().empty() ? fs::path(".") : path.parent_path(), ec)) {
    const std::string name = entry.path().filename().string();
    if (name.starts_with(prefix) && (but_of_ranks == 0 || !name.ends_with(own)) && name.find(".tmp-") == std::string::npos)
      fs::remove(entry.path(), ec);
  }
}

}  // namespace

void write_checkpoint(const Model& model, const State& state, const std::filesystem::path& path) {
  if (!state.exchange) {
    write_atomically(path, [&](Writer& w) {
      write_head(w, magic, model);
      fields(w, state);
    });
    return;
  }
  Exchange& exchange = *state.exchange;
  SplitIndex index;
  index.ranks = std::uint64_t(exchange.ranks());
  index.step = state.step, index.time = state.time;
  index.lost = exchange.sum(state.lost), index.wall_work = exchange.sum(state.wall_work);
  index.energy_reference = state.energy_reference, index.energy_scale = state.energy_scale;
  index.energy_reference_set = state.energy_reference_set;
  index.loop_max_overlap_rel = state.loop_max_overlap_rel, index.loop_max_energy_gain = state.loop_max_energy_gain;
  const auto rank = std::uint64_t(exchange.rank());
  const std::vector<char> saved = exchange.saved();
  run_and_agree(&exchange, true, [&] {
    write_atomically(piece_path(path, rank, index.ranks), [&](Writer& w) {
      write_head(w, piece_magic, model);
      w.value(rank), w.value(index.ranks), w.value(index.step);
      fields(w, state);
      w.array(saved);
    });
  });
  run_and_agree(&exchange, writes_outputs(state), [&] {
    write_atomically(path, [&](Writer& w) {
      write_head(w, split_magic, model);
      index_fields(w, index);
    });
    remove_pieces(path, index.ranks);
  });
}

State read_checkpoint(const Model& model, const std::filesystem::path& path, std::shared_ptr<Exchange> exchange) {
  // Every rank reads its part; should one fail, all stop.
  State s;
  run_and_agree(exchange.get(), true, [&] { s = read_any(model, path, exchange); });
  return s;
}

std::string checkpoint_layout() { return std::string(magic, sizeof magic); }

void remove_checkpoint(const std::filesystem::path& path) {
  remove_pieces(path, 0);
  fs::remove(path);
}

}  // namespace dem
