#include "dem/checkpoint.hpp"

#include <fstream>

#include "core/atomic_file.hpp"
#include "core/error.hpp"

namespace dem {

namespace {

constexpr char magic[8] = {'D', 'F', 'C', 'K', 'P', 'T', '0', '4'};

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
}

}  // namespace

void write_checkpoint(const Model& model, const State& state, const std::filesystem::path& path) {
  Writer w;
  w.bytes.append(magic, sizeof magic);
  w.bytes.append(model.hash);
  fields(w, state);
  diefill::write_file_atomic(path, w.bytes);
}

State read_checkpoint(const Model& model, const std::filesystem::path& path) {
  Reader r{std::ifstream(path, std::ios::binary)};
  char head[sizeof magic];
  std::string hash(model.hash.size(), '\0');
  r.in.read(head, sizeof head);
  r.in.read(hash.data(), std::streamsize(hash.size()));
  if (!r.in || std::string(head, sizeof head) != std::string(magic, sizeof magic))
    throw diefill::InputError(path.string(), "", "not a diefill checkpoint", "Name a checkpoint file diefill wrote");
  if (hash != model.hash)
    throw diefill::InputError(path.string(), "model", "the checkpoint was written by a different scene or build",
                              "Resume with the scene that wrote it, or start afresh");
  State s;
  fields(r, s);
  if (!r.in) throw diefill::InputError(path.string(), "", "the checkpoint is truncated", "Start afresh");
  // The cross pairs' force buffers are scratch, refilled by the next force stage.
  s.cross_forces.force.assign(s.neighbours.cross_reverse.size(), Vec3::Zero());
  s.cross_forces.torque.assign(s.neighbours.cross_reverse.size(), Vec3::Zero());
  return s;
}

}  // namespace dem
