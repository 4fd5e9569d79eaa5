#pragma once
// The stepping loop every command shares: outputs at their cadence, progress, a clean stop on
// Ctrl-C with a checkpoint, and a failed stability check turned into a checkpoint plus
// StabilityError (exit status 3).
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "dem/model.hpp"
#include "dem/state.hpp"
#include "dem/step.hpp"

namespace pipeline {

// An output at its own cadence: at the start, every `every` seconds of simulated time, and at the end.
// Output n falls due at the loop's output origin + n·every and is written at the first step that
// reaches it (less half a step), so that a resumed loop writes what the uninterrupted one would.
struct Periodic {
  double every = 0;  // [s]
  std::function<void(const dem::State&)> action;
};

struct LoopOptions {
  double until = 0;  // simulated time to reach [s]
  std::string label = "simulating";
  std::filesystem::path checkpoint;  // written on a stop (stability or Ctrl-C)
  std::vector<Periodic> outputs;     // called in this order when several fall due together
  // Asked after the outputs of a step: true ends the loop there (a drained container).
  std::function<bool(const dem::State&)> finished;
  // Extra words for the progress line (grains in the cavity, ...).
  std::function<std::string(const dem::State&)> detail;
  // The state comes from this loop's checkpoint: its maxima so far carry on (LoopResult), and
  // its outputs from the first the interrupted loop had not reached (first_output_after_resume).
  bool resumed = false;
  // Where the outputs' cadence starts (Periodic); a resumed loop passes the interrupted one's
  // start. Unset: the state's time when the loop starts.
  std::optional<double> output_origin;
  // A smoke run's bound (PipelineScene::max_steps): the loop ends after this many steps, with
  // its closing outputs, as if it had reached `until`. 0: none.
  std::int64_t max_steps = 0;
};

// The first output of a cadence (`every` from `origin`) that a loop resumed at `time` has still
// to write: the interrupted loop wrote those due by its last step's start, time - dt.
std::int64_t first_output_after_resume(double origin, double every, double time, double dt);

struct LoopResult {
  std::int64_t steps = 0;
  double wall_s = 0;
  dem::StageTimes times;
  bool interrupted = false;  // Ctrl-C: a checkpoint was written
  bool finished_early = false;  // options.finished said so
  // Over the whole run, not its last step: the largest overlap over the grain radius, and the
  // largest energy gain the monitor measured (dem::StepCounters::energy_gain), so that a run
  // can be judged by what happened in it, not only by how it ended.
  double max_overlap_rel = 0;
  double max_energy_gain = 0;  // 0 when the energy never exceeded its budget
};

// The thread count of a run, a study or a calibration for its duration (0: leave it), restored
// afterwards so that a process running several dies or studies keeps its own setting: the one
// place a command's --threads (or the scene's threads) takes effect.
class ThreadCount {
 public:
  explicit ThreadCount(int threads);
  ~ThreadCount();
  ThreadCount(const ThreadCount&) = delete;
  ThreadCount& operator=(const ThreadCount&) = delete;

 private:
  int saved_;
};

// Installs the handler of Ctrl-C, SIGTERM and SIGUSR1 (once); a second signal kills the process as usual.
void install_interrupt_handler();
// Whether one of them arrived: the stages after the DEM loop stop their long steps on it.
bool stop_requested();

LoopResult run_until(const dem::Model& model, dem::State& state, const LoopOptions& options);

// Where a stepped run starts: from its checkpoint when asked to resume and one is there, else
// afresh (the state initialised; a resume without a checkpoint is said, as a warning). Split over
// ranks, every rank goes by what rank 0 finds. `before_reading` runs before the checkpoint replaces
// the state (a run's own outputs so far are read while the state still has its starting time).
// Returns whether the run resumed: LoopOptions::resumed.
bool start_or_resume(const dem::Model& model, dem::State& state, const std::filesystem::path& checkpoint, bool resume,
                     const std::string& name, const std::function<void()>& before_reading = {});

// Seconds per stage, as the reports write them.
nlohmann::json stage_times_json(const dem::StageTimes& times);

}  // namespace pipeline
