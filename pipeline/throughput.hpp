#pragma once
// How fast this machine runs a scene, for `diefill plan` (pipeline/run_plan.hpp): a kernel rate
// measured at every plan (the scene's powder poured in a box for a few hundred steps), the
// fastest per machine, thread count and DEM code kept, and a wall-time model, time = overhead +
// particle-steps / (rate × efficiency), whose two constants every finished run on this machine
// refines (timings.jsonl).
#include <filesystem>
#include <string>

#include "pipeline/plan.hpp"

namespace pipeline {

// The kernel's particle-steps per second at the scene's thread count: measured (about a second),
// or the fastest measured before on this machine (its processor, thread count and the DEM's
// source hash) as `cache` keeps it, if faster.
double kernel_rate(const scene::PipelineScene& scene, const GrainSizing& grains, const std::filesystem::path& cache);

// The defaults: fitted to six runs from fresh shoes on the development machine (ring and disc at
// α = 16, 11.3 and 8, two threads, 2026-12-06: 18-223 s, each within 18 % of the fit).
struct TimeModel {
  double overhead_s = 8;     // the die's field, the outputs, the pictures: what does not scale with the DEM
  double efficiency = 0.22;  // of the kernel's rate in a fill (walls, neighbour builds, fill curve)
  int runs = 0;             // finished runs it was fitted to (0: the defaults above)
  double predict(double particle_steps, double rate) const { return overhead_s + particle_steps / (rate * efficiency); }
};

// The model from this machine's finished runs in `cache` (three or more), else the defaults; a
// run recorded before the kernel was measured counts at today's `rate`.
TimeModel time_model(const std::filesystem::path& cache, double rate);

// Appends a finished run's particle-steps (its settling's and its pass's, as stepped) and its
// wall time to `cache`'s timings.jsonl, with the kernel rate of this machine when measured.
void record_timing(const std::filesystem::path& cache, double particle_steps, double wall_s, int threads);

// This machine and thread count, as the cache keys its rates: the processor's name, the
// hardware threads, the threads asked for and the DEM's source hash.
std::string machine_key(int threads);

}  // namespace pipeline
