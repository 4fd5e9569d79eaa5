#include "pipeline/outputs.hpp"

#include <fmt/core.h>
#include <omp.h>

#include <algorithm>
#include <cmath>

#include "core/atomic_file.hpp"
#include "core/log.hpp"
#include "core/sha256.hpp"
#include "dem/io.hpp"
#include "dem/step.hpp"
#include "pipeline/density_stage.hpp"
#include "pipeline/ensemble.hpp"
#include "pipeline/fem_stage.hpp"
#include "mesh/tetmesh.hpp"
#include "pipeline/fill_curve.hpp"
#include "pipeline/pictures.hpp"
#include "scene/physics_keys.hpp"

namespace pipeline {

namespace fs = std::filesystem;

namespace {

DensityOptions density_options(const scene::DensitySettings& density, const GrainSizing& grains) {
  DensityOptions ds;
  ds.voxel_m = density.voxel > 0 ? density.voxel : 2 * grains.diameter;
  ds.method = density.method;
  ds.smoothed_width_m = density.smoothed_width > 0 ? density.smoothed_width : 0.5 * grains.diameter;
  ds.coarse_graining = grains.alpha;
  return ds;
}

double powder_density(const FillWalls& walls) { return walls.spec.materials[std::size_t(walls.powder)].density; }

// The density field of the cavity's grains (none: a warning and an empty fill), of a seed
// ensemble the mean of its seeds' fields; the report's `fill` figures are then the seeds' means,
// each with its standard error beside it (pipeline/ensemble.hpp).
nlohmann::json write_density_field(const FillSetting& c, const Realisations& r, const fs::path& dir) {
  if (std::any_of(r.cavity.begin(), r.cavity.end(), [](const auto& grains) { return grains.empty(); })) {
    diefill::log::warn("{}: no grain entered the cavity; no density field", c.walls.die.name);
    return {{"mass_kg", 0.0}, {"fill_ratio", 0.0}, {"voxel_m", 0.0}};
  }
  const DensityOptions ds = density_options(c.scene.density, c.grains);
  std::vector<DensityResult> fields;
  std::vector<nlohmann::json> figures;
  for (const std::vector<post::Grain>& grains : r.cavity) {
    fields.push_back(compute_density(grains, c.walls.die, *c.walls.die_field, powder_density(c.walls), ds, c.walls.die.name));
    figures.push_back(statistics_json(fields.back().stats));
  }
  write_density(fields.size() == 1 ? fields.front() : mean_density(fields), dir, c.scene.pictures);
  nlohmann::json fill = figures.size() == 1 ? figures.front() : mean_with_stderr(figures);
  fill["voxel_m"] = ds.voxel_m;
  fill["smoothed_width_m"] = ds.smoothed_width_m;
  return fill;
}

// The FEM hand-off (fem/), on elements as large as the density voxels unless the scene says.
nlohmann::json write_fem_section(const FillSetting& c, const Realisations& r, const nlohmann::json& fill, const fs::path& dir) {
  if (fill.at("voxel_m").get<double>() <= 0 || c.scene.fem.elements == scene::FemElements::none) return nullptr;
  FemOptions settings = fem_options(c.grains.diameter, fill.at("voxel_m").get<double>(), c.scene.fem.element_size);
  settings.quadratic = c.scene.fem.elements == scene::FemElements::quadratic;
  settings.compaction = c.scene.fem.compaction == scene::FemCompaction::calculix;
  try {
    return write_fem_outputs(r.cavity, c.walls.die, *c.walls.die_field, powder_density(c.walls), fill.at("mass_kg"), settings, dir);
  } catch (const mesh::TetMeshingStopped&) {
    diefill::log::warn("{}: the FEM hand-off was stopped while its tetrahedra were meshed: no fem/; the fill's outputs are "
                       "written", c.walls.die.name);
    return nullptr;
  }
}

// The fill curve (CSV and chart; it ends at the field's mass, fill.mass_kg; an ensemble's with
// its band) and what the report says of it: the cavity's capacity (its volume full of solid
// material) and the strike-off.
nlohmann::json write_fill_curve_outputs(const FillSetting& c, const Realisations& r, const fs::path& dir) {
  const double capacity = c.walls.die.after.volume_m3 * powder_density(c.walls);
  const double strike_off = strike_off_time(c.shoe, geometry::bounding_box(c.walls.die.cavity).hi.x());
  if (r.curves.size() == 1) {
    write_fill_curve(r.curves.front(), capacity, dir / "fill_curve.csv");
  } else {
    const auto [curve, band] = mean_curve(r.curves);
    write_fill_curve(curve, capacity, dir / "fill_curve.csv", &band);
  }
  if (c.scene.pictures) draw_pictures({"fill_curve", (dir / "fill_curve.csv").string(), fmt::format("{:.9g}", strike_off)});
  return {{"cavity_capacity_kg", capacity},
          {"strike_off_s", strike_off},
          {"curve", "fill_curve.csv"}};
}


// The run's own checks that do not stop it (those that do, the monitor's overlap and energy
// limits, stop the run with status 3 and write no report): every grain the insertion made is
// counted at the end, none lost to a fault, and the FEM hand-off's elements are all right side out
// and hold the cavity's mass to 0.5 % (docs/INTERFACE.md, "stability"). Failed ones are warned.
nlohmann::json run_checks(const FillRecord& r, const nlohmann::json& fem) {
  nlohmann::json checks = {{"every_grain_counted", r.census.grains == r.census.inserted},
                           {"no_grain_lost", r.census.lost == 0}};
  if (!fem.is_null()) {
    checks["fem_no_inverted_element"] = fem.at("inverted_elements").get<std::size_t>() == 0;
    checks["fem_mass_within_half_percent"] = std::abs(fem.at("mass_error_rel").get<double>()) <= fem_mass_tolerance;
  }
  std::string failed;
  for (const auto& [name, passed] : checks.items())
    if (!passed.get<bool>()) failed += (failed.empty() ? "" : ", ") + name;
  if (!failed.empty()) diefill::log::warn("{}: the run's checks failed: {} (report.json, stability.checks)", r.walls.die.name, failed);
  return checks;
}

nlohmann::json report_json(const FillRecord& r, const nlohmann::json& fill, const nlohmann::json& fem) {
  const scene::PipelineScene& s = r.scene;
  const mesh::PreparedDie& die = r.walls.die;
  const bool clumps = !s.powder.shape_mesh.empty();
  const double steps = double(r.fill.loop.steps);
  const nlohmann::json checks = run_checks(r, fem);
  return {
      {"die",
       {{"name", die.name},
        {"source", die.source},
        {"sha256", die.sha256},
        {"units", geometry::unit_name(die.unit)},
        {"units_guessed", die.unit_guessed},
        {"up_in_file", mesh::up_name(die.up)},
        {"up_found", die.up_found},
        {"parting", die.parting_z ? "widest section" : "flat opening"},
        {"part", die.part},
        {"cavity_volume_m3", die.after.volume_m3},
        {"triangles", die.before.triangles},
        {"repaired", !die.actions.empty()},
        {"repairs", die.actions},
        {"table_z_m", r.table_z}}},
      {"powder",
       {{"grains", r.census.inserted},
        {"grains_requested", r.settled.requested},
        {"total_grain_volume_m3", r.census.grain_volume_m3},
        {"material_density", r.walls.spec.materials[std::size_t(r.walls.powder)].density},
        {"coarse_graining", r.grains.alpha},
        {"grain_diameter_m", r.grains.diameter},
        {"shape", clumps ? s.powder.shape_mesh : "sphere"},
        {"spheres_per_grain", clumps ? r.fill.state.size() / std::max<std::size_t>(1, r.fill.state.bodies.size()) : std::size_t{1}}}},
      {"shoe",
       {{"length_m", r.shoe.length},
        {"width_m", r.shoe.width},
        {"width_requested_m", s.shoe.width},
        {"speed_m_s", s.motion.speed},
        {"passes", s.motion.passes}}},
      {"fill", fill},
      {"fem", fem},
      {"particles",
       {{"inserted", r.census.inserted},
        {"in_cavity", r.census.in_cavity},
        {"in_shoe", r.census.in_shoe},
        {"elsewhere", r.census.elsewhere},
        {"spilled", r.census.spilled},
        {"lost", r.census.lost}}},
      {"timing",
       {{"wall_s", r.wall_s},
        {"steps", r.fill.loop.steps},
        {"dt_s", r.fill.dt},
        {"particle_steps_per_s", steps * double(r.fill.state.size()) / std::max(1e-9, r.fill.loop.wall_s)},
        {"ranks", r.ranks},
        {"threads_per_rank", omp_get_max_threads()},
        {"stages", stage_times_json(r.fill.loop.times)}}},
      {"run",
       {{"version", DIEFILL_VERSION},
        {"dem_source_sha256", std::string(dem::source_hash())},
        {"seed", s.seed},
        {"scene_sha256", scene_hash(s)}}},
      {"final_state_sha256", dem::state_hash(r.fill.state)},
      {"stability",
       {{"max_overlap_rel", r.fill.loop.max_overlap_rel},
        {"max_energy_gain", r.fill.loop.max_energy_gain},
        {"checks", checks},
        {"checks_passed", std::all_of(checks.begin(), checks.end(), [](const nlohmann::json& c) { return c.get<bool>(); })},
        {"warnings", diefill::log::take_warnings()}}}};
}

}  // namespace

// Of every key that shapes the result (not where it is written, nor how fast) and the materials,
// but the seed (run.seed beside it): runs with equal hashes are the same scene, and with equal
// seeds too the same run (`diefill compare` tells seeds of one scene from different scenes).
std::string scene_hash(const scene::PipelineScene& s) {
  scene::PipelineScene unseeded = s;
  unseeded.seed = 0;
  std::string text;
  for (const scene::Shapes what : {scene::Shapes::die, scene::Shapes::settling, scene::Shapes::run}) text += scene::shaping_values(scene::pipeline_keys(), what, unseeded);
  return diefill::sha256_hex(text + scene::describe_materials(s.spec));
}

FillProducts write_fill_products(const FillSetting& setting, const Realisations& r, const fs::path& dir) {
  FillProducts p;
  p.fill = write_density_field(setting, r, dir);
  p.fill.update(write_fill_curve_outputs(setting, r, dir));
  p.fem = write_fem_section(setting, r, p.fill, dir);
  return p;
}

nlohmann::json write_fill_outputs(const FillRecord& r, const fs::path& dir) {
  diefill::StagingFolder out(dir);
  const auto [fill, fem] = write_fill_products({r.scene, r.walls, r.grains, r.shoe}, {{r.census.cavity}, {r.fill.curve}}, out.path());
  dem::write_particles_csv(r.fill.state, out / "particles.csv");
  dem::write_vtu(r.fill.state, out / "final.vtu");
  diefill::write_file_atomic(out / "scene.toml", describe(r.scene));
  const nlohmann::json report = report_json(r, fill, fem);
  diefill::write_file_atomic(out / "report.json", report.dump(2) + "\n");
  out.commit();
  diefill::log::info("{}: {} of {} grains in the cavity, fill ratio {:.3f}, mean solid fraction {:.3f} -> {}", r.walls.die.name,
                     r.census.in_cavity, r.census.grains, fill.value("fill_ratio", 0.0), fill.value("solid_fraction_mean", 0.0),
                     dir.string());
  return report;
}

}  // namespace pipeline
