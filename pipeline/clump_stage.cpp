#include "pipeline/clump_stage.hpp"

#include "core/log.hpp"
#include "mesh/import.hpp"
#include "mesh/repair.hpp"

namespace pipeline {

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

}  // namespace pipeline
