// `diefill clump MESH`: the multi-sphere template of a grain shape, and its errors against the
// number of spheres, from which a user picks the cheapest clump that is faithful enough.
#include <fmt/core.h>

#include "cli/commands.hpp"
#include "pipeline/clump_stage.hpp"

namespace cli {

int run_clump(const ClumpCommand& c) {
  const geometry::ClumpTemplate clump =
      pipeline::build_clump({c.mesh, geometry::parse_unit(c.units, "--units"), c.tolerance, c.max_spheres, c.seed});
  // -o names the template file when it ends in .json (docs/INTERFACE.md), else a folder for it.
  const std::filesystem::path json = pipeline::write_clump_outputs(clump, c.mesh, c.output);
  fmt::print("{}: {} spheres, volume error {:.4f}, Hausdorff error {:.4f} (tolerance {}), equivalent diameter {:.4g} mm -> {}\n",
             c.mesh.string(), clump.spheres.size(), clump.volume_error, clump.hausdorff_error, c.tolerance,
             clump.equivalent_diameter_m * 1e3, json.string());
  return 0;
}

}  // namespace cli
