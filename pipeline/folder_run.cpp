#include "pipeline/folder_run.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cctype>
#include <set>
#include <string>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "pipeline/die_fill.hpp"
#include "pipeline/run_loop.hpp"

namespace pipeline {

namespace fs = std::filesystem;

namespace {

// The mesh formats a CAD tool writes and assimp reads; anything else in the folder (a README, a
// log, a scene) is not a die and is passed over, with a note.
bool is_mesh(const fs::path& p) {
  static const std::set<std::string> formats = {".stl", ".obj", ".ply", ".off", ".3ds", ".fbx", ".dae", ".gltf", ".glb", ".3mf", ".amf"};
  std::string extension = p.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return formats.count(extension) > 0;
}

std::vector<fs::path> meshes_in(const fs::path& folder) {
  std::vector<fs::path> files, others;
  for (const auto& entry : fs::directory_iterator(folder))
    if (entry.is_regular_file()) (is_mesh(entry.path()) ? files : others).push_back(entry.path());
  std::sort(files.begin(), files.end());
  for (const fs::path& other : others) diefill::log::info("{}: not a mesh file; passed over", other.string());
  if (files.empty())
    throw diefill::InputError(folder.string(), "", "the folder holds no mesh files", "Put die meshes (STL, OBJ, PLY, ...) into it");
  return files;
}

}  // namespace

int run_folder(const scene::PipelineScene& scene, const fs::path& folder, bool resume, const std::shared_ptr<dem::Exchange>& ranks) {
  const bool root = !ranks || ranks->rank() == 0;
  std::string csv = "die,status,grains_in_cavity,fill_ratio,solid_fraction_mean,solid_fraction_std,solid_fraction_min,solid_fraction_max,message\n";
  std::string md = "| die | status | grains in cavity | fill ratio | mean | std | min | max |\n|---|---|---|---|---|---|---|---|\n";
  int refused = 0, unstable = 0;
  const auto record_failure = [&](const fs::path& mesh, const char* status, std::string message) {
    if (root) fmt::print(stderr, "error: {}\n", message);
    std::replace(message.begin(), message.end(), ',', ';');
    std::replace(message.begin(), message.end(), '|', '/');
    csv += fmt::format("{},{},,,,,,,{}\n", mesh.stem().string(), status, message);
    md += fmt::format("| {} | {}: {} | | | | | | |\n", mesh.stem().string(), status, message);
  };
  for (const fs::path& mesh : meshes_in(folder)) {
    try {
      const DieRun run = run_die_fill(scene, mesh, resume, ranks);
      // Stopped while its outputs were written (the FEM hand-off): that die is done, no other starts.
      if (run.interrupted || stop_requested()) return diefill::exit_interrupted;
      if (!root) continue;
      const auto& fill = run.report["fill"];
      const auto value = [&](const char* key) { return fill.value(key, 0.0); };
      csv += fmt::format("{},ok,{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},\n", run.die, run.report["particles"]["in_cavity"].get<std::size_t>(),
                         value("fill_ratio"), value("solid_fraction_mean"), value("solid_fraction_std"),
                         value("solid_fraction_min"), value("solid_fraction_max"));
      md += fmt::format("| {} | ok | {} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} |\n", run.die,
                        run.report["particles"]["in_cavity"].get<std::size_t>(), value("fill_ratio"),
                        value("solid_fraction_mean"), value("solid_fraction_std"), value("solid_fraction_min"),
                        value("solid_fraction_max"));
    } catch (const diefill::InputError& e) {
      ++refused;
      record_failure(mesh, "refused", e.what());
    } catch (const diefill::StabilityError& e) {
      ++unstable;  // the next die may still run; its checkpoint stays for a resume
      record_failure(mesh, "stopped", e.what());
    }
  }
  if (root) {
    diefill::write_file_atomic(scene.output.directory / "summary.csv", csv);
    diefill::write_file_atomic(scene.output.directory / "summary.md", md);
    fmt::print("{}", md);
  }
  return unstable > 0 ? diefill::exit_unstable : refused > 0 ? diefill::exit_bad_input : diefill::exit_ok;
}

}  // namespace pipeline
