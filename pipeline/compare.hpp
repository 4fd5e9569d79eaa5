#pragma once
// `diefill compare RUN_A RUN_B`: two runs of one die side by side (docs/INTERFACE.md, "Compare
// and sweep"): their reports' fill statistics and the difference of their density fields.
#include <filesystem>
#include <nlohmann/json.hpp>

namespace pipeline {

// Reads RUN_A and RUN_B (folders a run wrote: report.json and density.vdb) and writes into `out`
// compare.json (the summary it returns), difference.vdb (B - A of the solid fraction, and of the
// smoothed one when both have it) and compare.png. Throws InputError when a folder is not a
// run's, or the two are of different dies or on different grids.
nlohmann::json compare_runs(const std::filesystem::path& run_a, const std::filesystem::path& run_b,
                            const std::filesystem::path& out);

}  // namespace pipeline
