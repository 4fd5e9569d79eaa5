#pragma once
// `diefill run DIE --seeds N` (docs/INTERFACE.md, "Seed ensembles"): N realisations of one scene
// that differ in the powder's random packing alone, each the very run `--seed K` gives, in a
// folder of its own, and their mean with the standard error of that mean: the field per voxel,
// every fill figure of the report, the fill curve, and the FEM hand-off per element. One run's
// noise (5.6 % per 1.6 mm voxel on the default ring) falls as 1/√N.
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "dem/exchange.hpp"
#include "pipeline/die_fill.hpp"
#include "pipeline/fill_curve.hpp"

namespace pipeline {

// Over blocks of one shape (each seed's report `fill`, say): every number their mean and, beside
// each number that differs between them, `<key>_stderr`, the standard error of that mean; arrays
// of numbers element by element (arrays of other lengths, and text and flags, the first's).
nlohmann::json mean_with_stderr(const std::vector<nlohmann::json>& blocks);

// The seeds' fill curves sample by sample (one cadence: sample n falls at the same time in each,
// to a time step; the mean ends with the shortest): the mean curve and its band.
std::pair<std::vector<FillSample>, FillBand> mean_curve(const std::vector<std::vector<FillSample>>& curves);

// Seeds s, s+1, ..., s+N-1 (s: the scene's simulation.seed) as a sweep over simulation.seed
// (pipeline/sweep.hpp: each into OUT/simulation.seed=K/<die>/, one cache; the sweep's table
// beside them), then their ensemble into OUT/<die>/: density.vdb and .vti with the mean fields
// and their standard errors, report.json (each varying figure the mean with `_stderr` beside
// it, and an `ensemble` block), fill_curve.csv with its band, fem/ with each element's mean and
// standard error, the pictures. InputError for N < 2. Interrupted when a seed's run was.
DieRun run_ensemble(const std::function<scene::PipelineScene(const std::vector<std::string>& overrides)>& load, int seeds,
                    const std::shared_ptr<dem::Exchange>& ranks);

}  // namespace pipeline
