// `diefill run`: the pipeline. So far the mesh stage: each die is imported, checked, repaired
// and turned into its signed-distance field; the DEM and density stages follow.
#include <fmt/core.h>

#include <nlohmann/json.hpp>

#include "app/commands.hpp"
#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "mesh/die.hpp"

namespace app {

namespace fs = std::filesystem;

namespace {

std::vector<fs::path> die_files(const fs::path& target) {
  if (!fs::is_directory(target)) return {target};
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(target))
    if (entry.is_regular_file()) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  if (files.empty())
    throw diefill::InputError(target.string(), "", "the folder holds no mesh files",
                              "Put die meshes (STL, OBJ, PLY, ...) into it");
  return files;
}

}  // namespace

int run_pipeline(const RunCommand& c) {
  mesh::DieOptions options = mesh::die_options_for_grains(0.5e-3, 0.25e-3);
  options.unit = mesh::parse_unit(c.units, "--units");
  for (const fs::path& file : die_files(c.target)) {
    const mesh::PreparedDie die = mesh::prepare_die(file, options, c.out / ".cache");
    const fs::path dir = c.out / die.name;
    die.sdf.write(dir / "sdf.vdb");
    const nlohmann::json report = {
        {"die",
         {{"name", die.name},
          {"source", die.source},
          {"sha256", die.sha256},
          {"cavity_volume_m3", die.after.volume_m3},
          {"triangles", die.before.triangles},
          {"repaired", !die.actions.empty()},
          {"repairs", die.actions}}}};
    diefill::write_file_atomic(dir / "report.json", report.dump(2) + "\n");
    fmt::print("{}: mesh stage done ({} triangles, {} voxels{}) -> {}\n", die.name,
               die.after.triangles, die.sdf.active_voxels(), die.sdf_from_cache ? ", cached" : "",
               dir.string());
  }
  fmt::print("note: the DEM, density and report stages are not built yet; this run stops after "
             "the mesh stage\n");
  return 0;
}

}  // namespace app
