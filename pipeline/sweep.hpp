#pragma once
// `diefill run DIE --sweep KEY=V1,V2,...`: independent runs of one die over the values of one
// scene key (docs/INTERFACE.md, "Compare and sweep").
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "dem/exchange.hpp"
#include "pipeline/die_fill.hpp"

namespace pipeline {

struct Sweep {
  std::string key;                  // a scene key, as --set names it: motion.speed
  std::vector<std::string> values;  // as --set would give them
};

// Parses KEY=V1,V2,...; throws InputError naming --sweep when it is not of that form.
Sweep parse_sweep(const std::string& text);

// Runs each value: the scene `load` gives with KEY=value among its overrides, into
// OUT/<KEY>=<value>/<die>/ (OUT: the scene's output.directory) with one cache for all, so each
// case is the very run `--set KEY=value` gives. Then OUT/sweep_<KEY>.csv, .json and .png: fill
// ratio, mass and grains against the value. Every case's scene is loaded (and a bad value
// refused) before the first run; output.* keys are refused. Returns the runs (empty reports
// off rank 0).
std::vector<DieRun> run_sweep(const std::function<scene::PipelineScene(const std::vector<std::string>& overrides)>& load,
                              const Sweep& sweep, const std::shared_ptr<dem::Exchange>& ranks);

}  // namespace pipeline
