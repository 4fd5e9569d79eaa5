#include "pipeline/run_loop.hpp"

#include <fmt/core.h>
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>

#include "core/error.hpp"
#include "core/log.hpp"
#include "core/progress.hpp"
#include "dem/checkpoint.hpp"

namespace pipeline {

namespace {
std::atomic<bool> g_interrupted{false};

// Ctrl-C (SIGINT); SIGTERM, which a batch scheduler sends before it kills a job, and which
// mpirun sends every rank on Ctrl-C; SIGUSR1, which mpirun forwards to every rank as it is. A
// second signal ends the process as usual.
constexpr int stop_signals[] = {SIGINT, SIGTERM, SIGUSR1};

void on_interrupt(int) {
  g_interrupted = true;
  for (int signal : stop_signals) std::signal(signal, SIG_DFL);
}

// A failed check stops the run, with a checkpoint to look at where the run keeps one.
[[noreturn]] void stop_unstable(const dem::Model& model, dem::State& s, const LoopOptions& o, const dem::StepReport& report) {
  if (!o.checkpoint.empty()) dem::write_checkpoint(model, s, o.checkpoint);
  throw diefill::StabilityError(report.message + (o.checkpoint.empty() ? "" : fmt::format(" (checkpoint: {})", o.checkpoint.string())),
                                model.dt);
}

void track_checks(dem::State& s) {
  s.loop_max_overlap_rel = std::max(s.loop_max_overlap_rel, s.counters.checked_overlap_rel);
  s.loop_max_energy_gain = std::max(s.loop_max_energy_gain, s.counters.energy_gain);
}
}  // namespace

ThreadCount::ThreadCount(int threads) : saved_(omp_get_max_threads()) {
  if (threads > 0) omp_set_num_threads(threads);
}
ThreadCount::~ThreadCount() { omp_set_num_threads(saved_); }

void install_interrupt_handler() {
  for (int signal : stop_signals) std::signal(signal, on_interrupt);
}

bool stop_requested() { return g_interrupted; }

bool start_or_resume(const dem::Model& model, dem::State& state, const std::filesystem::path& checkpoint, bool resume,
                     const std::string& name, const std::function<void()>& before_reading) {
  const bool found = state.exchange ? state.exchange->max(state.exchange->rank() == 0 && std::filesystem::exists(checkpoint) ? 1.0 : 0.0) > 0
                                    : std::filesystem::exists(checkpoint);
  if (resume && found) {
    if (before_reading) before_reading();
    state = dem::read_checkpoint(model, checkpoint, state.exchange);
    diefill::log::info("{}: resumed at t = {:.6g} s", name, state.time);
    return true;
  }
  if (resume) diefill::log::warn("{}: --resume: no checkpoint at {}; the run starts afresh", name, checkpoint.string());
  dem::initialize(model, state);
  return false;
}

std::int64_t first_output_after_resume(double origin, double every, double time, double dt) {
  // Due by time - dt with the loop's half-step margin: origin + n·every - dt/2 <= time - dt.
  return std::max<std::int64_t>(0, std::int64_t(std::floor((time - 0.5 * dt - origin) / every)) + 1);
}

LoopResult run_until(const dem::Model& model, dem::State& s, const LoopOptions& o) {
  LoopResult result;
  diefill::Stopwatch clock;
  diefill::Progress progress(o.label, o.until);
  const double start = s.time;
  const double origin = o.output_origin.value_or(s.time);
  std::vector<std::int64_t> next_output(o.outputs.size(), 0);  // of each cadence (Periodic)
  if (o.resumed)
    for (std::size_t k = 0; k < o.outputs.size(); ++k)
      next_output[k] = first_output_after_resume(origin, o.outputs[k].every, s.time, model.dt);
  const std::int64_t grains = s.exchange ? s.exchange->sum(std::int64_t(s.owned())) : std::int64_t(s.size());
  if (!o.resumed) s.loop_max_overlap_rel = s.loop_max_energy_gain = 0;
  while (s.time < o.until - 0.5 * model.dt && (o.max_steps == 0 || result.steps < o.max_steps)) {
    bool output = false;
    for (std::size_t k = 0; k < o.outputs.size(); ++k)
      if (s.time >= origin + double(next_output[k]) * o.outputs[k].every - 0.5 * model.dt) {
        o.outputs[k].action(s);
        ++next_output[k];
        output = true;
      }
    if (output && o.finished && o.finished(s)) {
      result.finished_early = true;
      break;
    }
    // Split over ranks, Ctrl-C reaches the ranks at different steps: the step makes them agree, so
    // that all stop after the same one and write one checkpoint together.
    s.counters.stop_asked = g_interrupted;
    const dem::StepReport report = dem::step(model, s, &result.times);
    ++result.steps;
    track_checks(s);
    if (report.status != dem::StepStatus::ok) stop_unstable(model, s, o, report);
    if (s.counters.stop_agreed) {
      if (!o.checkpoint.empty()) dem::write_checkpoint(model, s, o.checkpoint);
      result.interrupted = true;
      break;
    }
    if ((result.steps & 63) == 0) {
      const double rate = double(result.steps) * double(grains) / std::max(1e-9, clock.seconds());
      progress.update(s.time - start, fmt::format("t = {:.4g} s, {:.3g} particle-steps/s{}", s.time, rate,
                                                  o.detail ? ", " + o.detail(s) : std::string()));
    }
  }
  if (const dem::StepReport last = dem::check_last_step(model, s); last.status != dem::StepStatus::ok) stop_unstable(model, s, o, last);
  track_checks(s);
  if (!result.interrupted && !result.finished_early)
    for (const Periodic& p : o.outputs) p.action(s);
  result.max_overlap_rel = s.loop_max_overlap_rel, result.max_energy_gain = s.loop_max_energy_gain;
  result.wall_s = clock.seconds();
  progress.finish(fmt::format("{} steps, {:.3g} particle-steps/s", result.steps,
                              double(result.steps) * double(grains) / std::max(1e-9, result.wall_s)));
  return result;
}

nlohmann::json stage_times_json(const dem::StageTimes& t) {
  return {{"neighbours", t.neighbours}, {"pair_forces", t.pair_forces}, {"sums", t.sums},
          {"wall_forces", t.wall_forces}, {"integration", t.integration}, {"monitor", t.monitor}};
}

}  // namespace pipeline
