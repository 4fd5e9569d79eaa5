// `diefill bench mpi-bed`: a bed of millions of grains split over MPI ranks, each rank building
// only its own share (bench/mpi_10m.sh; docs/ARCHITECTURE.md, "Domain decomposition"). It counts
// what a split run costs per rank: peak memory over the owned grains, global collectives and
// point-to-point messages per step, and times the set-up, the steps, the checkpoint and the
// particle output. With --resume it goes on from a checkpoint, on any rank count.
#include "bench/mpi_bed.hpp"

#include <fmt/core.h>
#include <sys/resource.h>

#include <cmath>
#include <cstring>

#include "core/error.hpp"
#include "core/log.hpp"
#include "core/timer.hpp"
#include "dem/checkpoint.hpp"
#include "dem/distributed.hpp"
#include "dem/io.hpp"
#include "dem/step.hpp"

namespace bench {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The bed: 1 mm grains of the LIGGGHTS reference material (cases.cpp) on a simple cubic
// lattice a hair tighter than the grains (every grain touches its six neighbours), 40 layers
// deep and four times as long as wide, so that cuts across its length give the ranks slabs.
constexpr double radius = 0.5e-3, pitch = 2 * radius * (1 - 2e-4);
constexpr std::int64_t layers = 40;
// Random velocities of up to this speed per component stir the bed, so that the lists are rebuilt
// every few tens of steps (skin below).
constexpr double stir_speed = 0.3, skin = 0.1e-3;

struct Bed {
  std::int64_t grains, wide, long_;  // lattice sites across (y) and along (x); layers in z
};

Bed bed_of(std::int64_t grains) {
  const auto wide = std::max<std::int64_t>(1, std::llround(std::sqrt(double(grains) / double(4 * layers))));
  return {grains, wide, (grains + wide * layers - 1) / (wide * layers)};
}

// A number in [-1, 1) from a grain's id alone (splitmix64), so that any rank count draws alike.
double from_id(std::uint64_t id, std::uint64_t salt) {
  std::uint64_t z = id * 3 + salt + 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return double(z >> 11) * 0x1.0p-52 - 1.0;
}

// This rank's share: lattice sites [rank·N/ranks, (rank+1)·N/ranks) in x-major order, a slab.
dem::State share_of_bed(const Bed& bed, int rank, int ranks) {
  const std::int64_t first = bed.grains * rank / ranks, last = bed.grains * (rank + 1) / ranks;
  dem::State s;
  const std::size_t n = std::size_t(last - first);
  for (auto* a : {&s.x, &s.v, &s.w, &s.f, &s.torque}) a->reserve(n);
  for (auto* a : {&s.radius, &s.mass}) a->reserve(n);
  s.id.reserve(n), s.material.reserve(n), s.active.reserve(n), s.body.reserve(n);
  for (std::int64_t k = first; k < last; ++k) {
    const std::int64_t l = k % layers, j = k / layers % bed.wide, i = k / layers / bed.wide;
    const dem::Vec3 x(radius + double(i) * pitch, radius + double(j) * pitch, radius + double(l) * pitch);
    const auto id = std::uint64_t(k);
    s.add_sphere(k, x, radius, 2500, 0, stir_speed * dem::Vec3(from_id(id, 1), from_id(id, 2), from_id(id, 3)));
  }
  return s;
}

dem::ModelSpec bed_spec(const Bed& bed) {
  dem::Material m;
  m.name = "reference";
  m.density = 2500, m.youngs_modulus = 5e6, m.poisson_ratio = 0.3, m.restitution = 0.5;
  m.sliding_friction = 0.5, m.rolling_friction = 0.1;
  dem::ModelSpec spec;
  spec.materials = {m};
  spec.law.normal = "hertz";
  spec.law.tangential = "mindlin";
  spec.law.rolling = "cdt";
  spec.skin = skin;
  spec.max_impact_speed = 2 * std::sqrt(3.0) * stir_speed;
  spec.gravity = dem::Vec3(0, 0, -9.81);
  const dem::Vec3 hi(double(bed.long_) * pitch + 2 * radius, double(bed.wide) * pitch + 2 * radius, 0);
  spec.planes = {{dem::Vec3::Zero(), dem::Vec3::UnitZ(), 0, "floor"},
                 {dem::Vec3::Zero(), dem::Vec3::UnitX(), 0, "side"},
                 {dem::Vec3(hi.x(), 0, 0), -dem::Vec3::UnitX(), 0, "side"},
                 {dem::Vec3::Zero(), dem::Vec3::UnitY(), 0, "side"},
                 {dem::Vec3(0, hi.y(), 0), -dem::Vec3::UnitY(), 0, "side"}};
  spec.domain = {dem::Vec3::Constant(-2e-3), dem::Vec3(hi.x(), hi.y(), double(layers) * pitch + 0.05) + dem::Vec3::Constant(2e-3)};
  return spec;
}

double peak_resident_bytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_maxrss) * 1024.0;  // Linux: kilobytes
}

// The grains over every rank, and their total momentum.
struct Census {
  std::int64_t grains = 0;
  dem::Vec3 momentum = dem::Vec3::Zero();
  double momentum_scale = 0;  // Σ m |v|: what rounding in the sum is measured against
};
Census census(dem::Exchange& exchange, const dem::State& s) {
  std::vector<double> mine(5, 0.0);
  for (std::size_t i = 0; i < s.owned(); ++i) {
    for (int a = 0; a < 3; ++a) mine[std::size_t(a)] += s.mass[i] * s.v[i][a];
    mine[3] += s.mass[i] * s.v[i].norm();
  }
  mine[4] = double(s.owned());
  Census c;
  const std::vector<double> all = exchange.all_gather(mine);
  for (std::size_t at = 0; at < all.size(); at += 5) {
    c.momentum += dem::Vec3(all[at], all[at + 1], all[at + 2]);
    c.momentum_scale += all[at + 3];
    c.grains += std::int64_t(all[at + 4]);
  }
  return c;
}

// One hash of every rank's state (dem::state_hash), in rank order.
std::string split_hash(dem::Exchange& exchange, const dem::State& s) {
  const std::string mine = dem::state_hash(s);
  const std::vector<char> all = exchange.gather(std::vector<char>(mine.begin(), mine.end()));
  dem::State digest;  // the ranks' hashes as the ids of a state, hashed once more
  for (std::size_t at = 0; at + 8 <= all.size(); at += 8) {
    std::int64_t v = 0;
    std::memcpy(&v, all.data() + at, 8);
    digest.id.push_back(v);
  }
  return dem::state_hash(digest);
}

json census_json(const Census& c) {
  return {{"grains", c.grains}, {"momentum", {c.momentum.x(), c.momentum.y(), c.momentum.z()}}, {"momentum_scale", c.momentum_scale}};
}

}  // namespace

json run_mpi_bed(const Request& c, const std::shared_ptr<dem::Exchange>& exchange) {
  if (!exchange)
    throw diefill::InputError("bench mpi-bed", "mpirun", "the case measures a run split over MPI ranks",
                              "Run it under mpirun (bench/mpi_10m.sh)");
  dem::Exchange& ranks = *exchange;
  const Bed bed = bed_of(c.grains);
  const fs::path out = c.cache / "mpi-bed";
  const fs::path checkpoint = out / "checkpoint.bin";
  diefill::Stopwatch clock;
  dem::State s = share_of_bed(bed, ranks.rank(), ranks.ranks());
  s.exchange = exchange;
  const dem::Model model = dem::compile_model(bed_spec(bed), s, "mpi-bed");
  json result = {{"case", "mpi-bed"}, {"grains", bed.grains}, {"ranks", ranks.ranks()}, {"dt_s", model.dt},
                 {"lattice", {{"along", bed.long_}, {"across", bed.wide}, {"layers", layers}}}};
  if (!c.resume.empty()) {
    s = {};
    s = dem::read_checkpoint(model, c.resume, exchange);
    result["resumed_from"] = c.resume.string();
    result["resumed_at_step"] = s.step;
    result["census_at_resume"] = census_json(census(ranks, s));
  } else {
    dem::initialize(model, s);
  }
  const double setup_s = ranks.max(clock.seconds());
  // The steps, timed and counted apart from the checkpoint written on the way.
  double step_s = 0, checkpoint_s = 0;
  std::int64_t collectives = 0, messages = 0, bytes = 0, rebuilds = 0, cuts = 0, steps = 0;
  while (s.step < c.steps) {
    if (c.checkpoint_at > 0 && s.step == c.checkpoint_at && c.resume.empty()) {
      ranks.max(0);  // every rank starts the clock together
      clock.restart();
      dem::write_checkpoint(model, s, checkpoint);
      checkpoint_s += ranks.max(clock.seconds());
      result["census_at_checkpoint"] = census_json(census(ranks, s));
    }
    const std::int64_t before[] = {ranks.global_collectives(), ranks.messages_sent(), ranks.bytes_sent(), s.neighbours.builds, ranks.cuts()};
    clock.restart();
    if (const dem::StepReport r = dem::step(model, s); r.status != dem::StepStatus::ok) throw diefill::StabilityError(r.message, model.dt);
    step_s += clock.seconds();
    collectives += ranks.global_collectives() - before[0], messages += ranks.messages_sent() - before[1];
    bytes += ranks.bytes_sent() - before[2], rebuilds += s.neighbours.builds - before[3], cuts += ranks.cuts() - before[4];
    ++steps;
  }
  step_s = ranks.max(step_s);
  const double per_step = 1.0 / double(std::max<std::int64_t>(1, steps));
  // Every rank alike: the same collectives; the messages, per rank.
  const std::vector<double> traffic = ranks.all_gather({double(messages) * per_step, double(bytes) * per_step});
  double most_messages = 0, most_bytes = 0, all_messages = 0, all_bytes = 0;
  for (std::size_t r = 0; r < traffic.size(); r += 2) {
    most_messages = std::max(most_messages, traffic[r]), most_bytes = std::max(most_bytes, traffic[r + 1]);
    all_messages += traffic[r], all_bytes += traffic[r + 1];
  }
  // The particle output once, by the run from the start (a resumed one only times its steps).
  clock.restart();
  const fs::path particles = c.resume.empty() ? dem::write_vtu(s, out / "particles.vtu") : fs::path();
  const double output_s = ranks.max(clock.seconds());
  const double owned = double(std::max<std::size_t>(1, s.owned()));
  const double bytes_per_owned = ranks.max(peak_resident_bytes() / owned);
  result["state_bytes_per_owned_grain"] = ranks.max(double(s.memory_bytes()) / owned);  // the arrays alone, ghosts' included
  result.update({{"steps", steps},
                 {"final_step", s.step},
                 {"rebuilds", rebuilds},
                 {"cuts", cuts},
                 {"global_collectives_per_step", double(collectives) * per_step},
                 {"messages_per_rank_per_step", {{"largest", most_messages}, {"mean", all_messages / ranks.ranks()}}},
                 {"bytes_per_rank_per_step", {{"largest", most_bytes}, {"mean", all_bytes / ranks.ranks()}}},
                 {"bytes_per_owned_grain", bytes_per_owned},
                 {"setup_s", setup_s},
                 {"step_s", step_s},
                 {"particle_steps_per_s", double(bed.grains) * double(steps) / std::max(1e-9, step_s)},
                 {"checkpoint_s", checkpoint_s},
                 {"particle_output_s", output_s},
                 {"particle_output", particles.string()},
                 {"census_at_end", census_json(census(ranks, s))},
                 {"state_hash", split_hash(ranks, s)}});
  diefill::log::info("bench mpi-bed: {} grains on {} ranks, {} steps in {:.3g} s", bed.grains, ranks.ranks(), steps, step_s);
  return result;
}

}  // namespace bench
