#include "app/clump_stage.hpp"

#include "core/log.hpp"
#include "mesh/import.hpp"
#include "mesh/repair.hpp"

namespace app {

mesh::ClumpTemplate build_clump(const ClumpRequest& request) {
  const mesh::ImportResult imported = mesh::import_mesh(request.mesh, {request.unit});
  const double size = mesh::bounding_box(imported.mesh).size().maxCoeff();
  // Repair may move the surface by a tenth of the clump tolerance at most.
  mesh::RepairOptions repair_options;
  repair_options.tolerance_m = 0.1 * request.tolerance * size;
  repair_options.max_hole_m = 0.05 * size;
  const mesh::RepairResult repaired = mesh::repair(imported.mesh, repair_options, request.mesh.string());
  for (const std::string& action : repaired.actions) diefill::log::info("{}: {}", request.mesh.string(), action);
  mesh::ClumpOptions options;
  options.tolerance = request.tolerance;
  options.max_spheres = request.max_spheres;
  options.seed = request.seed;
  return mesh::make_clump(repaired.mesh, options);
}

}  // namespace app
