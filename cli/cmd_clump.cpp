// `diefill clump MESH`: the multi-sphere template of a grain shape, and its errors against the
// number of spheres, from which a user picks the cheapest clump that is faithful enough.
#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "pipeline/clump_stage.hpp"
#include "cli/commands.hpp"
#include "pipeline/pictures.hpp"
#include "core/atomic_file.hpp"
#include "mesh/import.hpp"

namespace cli {

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

int run_clump(const ClumpCommand& c) {
  const geometry::ClumpTemplate clump =
      pipeline::build_clump({c.mesh, geometry::parse_unit(c.units, "--units"), c.tolerance, c.max_spheres, c.seed});

  // -o names the template file when it ends in .json (docs/INTERFACE.md), else a folder for it.
  const bool file = c.output.extension() == ".json";
  const fs::path json = file ? c.output : c.output / (c.mesh.stem().string() + ".json");
  const fs::path errors = json.parent_path() / (json.stem().string() + "_errors.csv");
  if (!json.parent_path().empty()) fs::create_directories(json.parent_path());
  diefill::write_file_atomic(json, mesh::clump_json(clump));
  std::string csv = "spheres,volume_error,hausdorff_error,relative_cost\n";
  for (const geometry::ClumpStep& step : clump.history)
    csv += fmt::format("{},{:.6g},{:.6g},{:.4g}\n", step.spheres, step.volume_error, step.hausdorff_error,
                       relative_clump_cost(step.spheres));
  diefill::write_file_atomic(errors, csv);
  pipeline::draw_pictures({"clump", errors.string()});
  fmt::print("{}: {} spheres, volume error {:.4f}, Hausdorff error {:.4f} (tolerance {}), equivalent diameter {:.4g} mm -> {}\n",
             c.mesh.string(), clump.spheres.size(), clump.volume_error, clump.hausdorff_error, c.tolerance,
             clump.equivalent_diameter_m * 1e3, json.string());
  return 0;
}

}  // namespace cli
