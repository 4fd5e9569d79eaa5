#include "pipeline/fem_stage.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <numeric>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "mesh/tetmesh.hpp"
#include "pipeline/pictures.hpp"
#include "pipeline/run_loop.hpp"
#include "postprocess/compaction.hpp"
#include "postprocess/ensemble_stats.hpp"

namespace pipeline {

namespace fs = std::filesystem;

namespace {

// The worked example's result: the punch force and the mean axial stress of the densest and the
// loosest quarter of the elements (by count), with every element's pair for the picture.
nlohmann::json compaction_example(const post::FemFill& fill, const fs::path& dir) {
  const post::CompactionSettings s;
  const post::CompactionResult r = post::run_compaction(fill, dir, s);
  std::vector<std::size_t> order(fill.element_fraction.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return fill.element_fraction[a] < fill.element_fraction[b]; });
  const std::size_t quarter = order.size() / 4;
  auto mean_stress = [&](std::size_t first, std::size_t last) {
    double sum = 0;
    for (std::size_t i = first; i < last; ++i) sum += r.element_axial_stress[order[i]];
    return sum / double(std::max<std::size_t>(1, last - first));
  };
  diefill::write_file_atomic(dir / "compaction.json",
                             nlohmann::json{{"solid_fraction", fill.element_fraction}, {"axial_stress_pa", r.element_axial_stress},
                                            {"axial_strain", s.axial_strain}, {"punch_force_n", r.punch_force_n}}
                                 .dump());
  draw_pictures({"compaction", (dir / "compaction.json").string()});
  return {{"axial_strain", s.axial_strain},
          {"punch_travel_m", r.punch_travel_m},
          {"punch_force_n", r.punch_force_n},
          {"loosest_quarter_axial_stress_pa", mean_stress(0, quarter)},
          {"densest_quarter_axial_stress_pa", mean_stress(order.size() - quarter, order.size())}};
}

}  // namespace

FemOptions fem_options(double grain_diameter, double density_voxel, double element_size) {
  FemOptions s;
  s.element_size_m = element_size > 0 ? element_size : density_voxel;
  // A quarter grain diameter: at half one, the elements along the walls read 0.02 above the
  // grains' own solid there (ring, 1.6 mm grains, tests/fem_wall_layer.py), at a quarter 0.007.
  s.sub_voxel_m = std::min(0.25 * grain_diameter, 0.125 * s.element_size_m);
  return s;
}

namespace {

// One realisation's fill, or a seed ensemble's: the mean of its realisations' element values on
// the one mesh (Mesh_3 is deterministic, and each is filled on a copy of it), with their
// standard errors.
post::FemFill fill_of_realisations(const geometry::TetMesh& tets, const std::vector<std::vector<post::Grain>>& realisations,
                                   const post::CavityShape& cavity, double sub_voxel, double material_density) {
  std::vector<post::FemFill> fills;
  for (const std::vector<post::Grain>& grains : realisations)
    fills.push_back(post::fill_elements(tets, grains, cavity, sub_voxel, material_density));
  if (fills.size() == 1) return std::move(fills.front());
  std::vector<std::vector<double>> fractions;
  for (const post::FemFill& f : fills) fractions.push_back(f.element_fraction);
  post::MeanAndError m = post::mean_and_error(fractions);
  post::FemFill mean = std::move(fills.front());
  mean.element_fraction = std::move(m.mean);
  mean.element_fraction_stderr = std::move(m.error);
  mean.solid_volume_m3 = 0;
  for (std::size_t e = 0; e < mean.element_fraction.size(); ++e) mean.solid_volume_m3 += mean.element_fraction[e] * mean.element_volume[e];
  mean.node_fraction = post::average_to_nodes(mean.mesh, mean.element_fraction, mean.element_volume);
  return mean;
}

}  // namespace

nlohmann::json write_fem_outputs(const std::vector<std::vector<post::Grain>>& realisations, const mesh::PreparedDie& die,
                                 const geometry::WallField& walls, double material_density, double mass_in_cavity_kg,
                                 const FemOptions& s, const fs::path& dir) {
  diefill::ChildWait wait;
  wait.stop = stop_requested;
  wait.waiting = [&](double seconds) {
    diefill::log::info("{}: FEM hand-off: meshing the cavity in tetrahedra of {:.3g} mm, {:.0f} s so far (Ctrl-C skips "
                       "the hand-off and keeps the fill; fem.element_size coarsens it)",
                       die.name, s.element_size_m * 1e3, seconds);
  };
  const geometry::TetMesh tets = mesh::tetrahedralise(die.cavity, {s.element_size_m, s.element_size_m / 200, 60}, die.source, wait);
  const geometry::TetQuality q = geometry::tet_quality(tets);
  const post::CavityShape cavity{[&](const post::Vec3& p) { return walls.signed_distance(p); }, die.after.bbox.lo,
                                 post::Vec3(die.after.bbox.hi.x(), die.after.bbox.hi.y(), die.table_z)};
  const post::FemFill fill = fill_of_realisations(tets, realisations, cavity, s.sub_voxel_m, material_density);
  const fs::path fem = dir / "fem";
  fs::create_directories(fem);
  const std::size_t nodes = post::write_fem(fill, s.quadratic, fmt::format("diefill fill of {} ({})", die.name, die.source), fem);
  const double mesh_volume = std::accumulate(fill.element_volume.begin(), fill.element_volume.end(), 0.0);
  const double mass = fill.solid_volume_m3 * material_density;
  const auto [lo, hi] = std::minmax_element(fill.element_fraction.begin(), fill.element_fraction.end());
  nlohmann::json j = {
      {"files", {"fem/fill.inp", "fem/fill_abaqus.inp", "fem/fill_calculix.inp", "fem/fill.vtu"}},
      {"element_type", s.quadratic ? "C3D10" : "C3D4"},
      {"elements", fill.mesh.tets.size()},
      {"nodes", nodes},
      {"element_size_m", s.element_size_m},
      {"sub_voxel_m", fill.sub_voxel_m},
      {"min_dihedral_deg", q.min_dihedral_deg},
      {"max_dihedral_deg", q.max_dihedral_deg},
      {"min_radius_ratio", q.min_radius_ratio},
      {"mean_radius_ratio", q.mean_radius_ratio},
      {"inverted_elements", q.inverted},
      {"dropped_boundary_slivers", fill.mesh.dropped_boundary_slivers},
      {"mesh_volume_m3", mesh_volume},
      {"volume_error_rel", mesh_volume / die.after.volume_m3 - 1},
      {"mass_kg", mass},
      {"mass_error_rel", mass_in_cavity_kg > 0 ? mass / mass_in_cavity_kg - 1 : 0.0},
      {"solid_fraction_min", *lo},
      {"solid_fraction_max", *hi}};
  if (!fill.element_fraction_stderr.empty()) {
    std::vector<double> sorted = fill.element_fraction_stderr;
    std::sort(sorted.begin(), sorted.end());
    j["solid_fraction_stderr_median"] = sorted[sorted.size() / 2];
    j["solid_fraction_stderr_max"] = sorted.back();
  }
  if (s.compaction) {
    try {
      j["compaction"] = compaction_example(fill, fem);
    } catch (const diefill::InputError& e) {
      diefill::log::warn("{}: the CalculiX compaction example did not run: {}", die.name, e.what());
    }
  }
  return j;
}

}  // namespace pipeline
