#include "pipeline/clump_stage.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "core/atomic_file.hpp"
#include "core/log.hpp"
#include "mesh/import.hpp"
#include "mesh/repair.hpp"
#include "pipeline/pictures.hpp"

namespace pipeline {

namespace fs = std::filesystem;

namespace {

// Time per step of a settled pack of 2000 clumps of n spheres over that of 2000 spheres,
// measured on 2 cores (tests/test_clump_dem.cpp, Benchmark.DISABLED_SettledClumpPacks):
// n = 1, 2, 4, 8 cost 2.34, 3.24, 4.21, 5.85; interpolated in log n, extended with the last slope.
double relative_clump_cost(int spheres) {
  static constexpr double cost[] = {2.34, 3.24, 4.21, 5.85};
  const double octave = std::log2(std::max(1, spheres));
  const int k = std::min(2, int(octave));
  return std::exp(std::log(cost[k]) + (octave - k) * (std::log(cost[k + 1]) - std::log(cost[k])));
}

}  // namespace

geometry::ClumpTemplate build_clump(const ClumpRequest& request) {
  const mesh::ImportResult imported = mesh::import_mesh(request.mesh, {request.unit});
  const mesh::RepairResult repaired =
      mesh::repair(imported.mesh, mesh::grain_repair_options(imported.mesh, request.tolerance), request.mesh.string());
  for (const std::string& action : repaired.actions) diefill::log::info("{}: {}", request.mesh.string(), action);
  mesh::ClumpOptions options;
  options.tolerance = request.tolerance;
  options.max_spheres = request.max_spheres;
  options.seed = request.seed;
  return mesh::make_clump(repaired.mesh, options);
}

fs::path write_clump_outputs(const geometry::ClumpTemplate& clump, const fs::path& mesh, const fs::path& out) {
  const fs::path json = out.extension() == ".json" ? out : out / (mesh.stem().string() + ".json");
  const fs::path errors = json.parent_path() / (json.stem().string() + "_errors.csv");
  if (!json.parent_path().empty()) fs::create_directories(json.parent_path());
  diefill::write_file_atomic(json, mesh::clump_json(clump));
  std::string csv = "spheres,volume_error,hausdorff_error,relative_cost\n";
  for (const geometry::ClumpStep& step : clump.history)
    csv += fmt::format("{},{:.6g},{:.6g},{:.4g}\n", step.spheres, step.volume_error, step.hausdorff_error,
                       relative_clump_cost(step.spheres));
  diefill::write_file_atomic(errors, csv);
  draw_pictures({"clump", errors.string()});
  return json;
}

}  // namespace pipeline
