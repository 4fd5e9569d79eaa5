// `diefill clump MESH`: the multi-sphere template of a grain shape, and its errors against the
// number of spheres, from which a user picks the cheapest clump that is faithful enough.
#include <fmt/core.h>

#include "app/commands.hpp"
#include "app/density_stage.hpp"
#include "core/atomic_file.hpp"
#include "core/log.hpp"
#include "mesh/clump.hpp"
#include "mesh/import.hpp"
#include "mesh/repair.hpp"

namespace app {

namespace fs = std::filesystem;

int run_clump(const ClumpCommand& c) {
  const mesh::LengthUnit unit = mesh::parse_unit(c.units, "--units");
  const mesh::ImportResult imported = mesh::import_mesh(c.mesh, {unit});
  const double size = mesh::bounding_box(imported.mesh).size().maxCoeff();
  // A grain's repair may move its surface by a tenth of the clump tolerance at most.
  mesh::RepairOptions repair_options;
  repair_options.tolerance_m = 0.1 * c.tolerance * size;
  repair_options.max_hole_m = 0.05 * size;
  const mesh::RepairResult repaired = mesh::repair(imported.mesh, repair_options, c.mesh.string());
  for (const std::string& action : repaired.actions) diefill::log::info("{}: {}", c.mesh.string(), action);

  mesh::ClumpOptions options;
  options.tolerance = c.tolerance;
  options.max_spheres = c.max_spheres;
  options.seed = c.seed;
  const mesh::ClumpTemplate clump = mesh::make_clump(repaired.mesh, options);

  const std::string stem = c.mesh.stem().string();
  fs::create_directories(c.output);
  diefill::write_file_atomic(c.output / (stem + ".json"), mesh::clump_json(clump));
  // Relative cost: member spheres per grain, what the pair loop and the wall queries scale with
  // at a given packing (issue 6's benchmark measures the real ratio).
  std::string csv = "spheres,volume_error,hausdorff_error,relative_cost\n";
  for (const mesh::ClumpStep& step : clump.history)
    csv += fmt::format("{},{:.6g},{:.6g},{}\n", step.spheres, step.volume_error, step.hausdorff_error, step.spheres);
  diefill::write_file_atomic(c.output / (stem + "_errors.csv"), csv);
  draw_pictures({"clump", (c.output / (stem + "_errors.csv")).string()});
  fmt::print("{}: {} spheres, volume error {:.4f}, Hausdorff error {:.4f} (tolerance {}), equivalent diameter {:.4g} mm -> {}\n",
             c.mesh.string(), clump.spheres.size(), clump.volume_error, clump.hausdorff_error, c.tolerance,
             clump.equivalent_diameter_m * 1e3, (c.output / (stem + ".json")).string());
  return 0;
}

}  // namespace app
