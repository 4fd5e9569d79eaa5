#include "pipeline/density_stage.hpp"

#include <fmt/core.h>


#include "core/error.hpp"
#include "core/log.hpp"
#include "pipeline/pictures.hpp"

namespace app {

namespace fs = std::filesystem;

DensityResult compute_density(const std::vector<post::Grain>& grains, const mesh::PreparedDie& die,
                              const mesh::WallField& walls, double material_density, const DensitySettings& s,
                              const std::string& particles_source) {
  if (!(s.voxel_m > 0)) throw diefill::InputError("density", "voxel", "must be positive", "Give the voxel edge");
  // The cavity: the free side of the tool below the table (or the inside of a container).
  const bool container = die.sdf.metadata().count("role") && die.sdf.metadata().at("role") == "container";
  const double table = die.table_z;
  const mesh::Box box = die.after.bbox;
  const post::Vec3 lo(box.lo.x(), box.lo.y(), box.lo.z()), hi(box.hi.x(), box.hi.y(), container ? box.hi.z() : table);
  // The cavity lies within its bounding box. Bounding by the box matters where the grid reaches
  // past the die's field (coarse voxels below a thin table): there the field reads "free".
  auto into_cavity = [&](const post::Vec3& p) {
    const double into_box = std::min((p - lo).minCoeff(), (hi - p).minCoeff());
    return std::min(walls.signed_distance(p), into_box);
  };
  std::size_t in_box = 0;
  for (const post::Grain& g : grains)
    in_box += (g.centre.array() >= lo.array()).all() && (g.centre.array() <= hi.array()).all();
  if (in_box == 0)
    throw diefill::InputError(particles_source, "positions",
                              fmt::format("none of its {} grains lies in the cavity of {} ({:.3g} to {:.3g} mm)",
                                          grains.size(), die.source, lo.minCoeff() * 1e3, hi.maxCoeff() * 1e3),
                              "Give the die the grains were simulated in, with the same units");

  DensityResult r;
  post::DensityField& f = r.field;
  f.grid = post::grid_covering(lo, hi, s.voxel_m, container ? lo.z() : table);
  f.material_density = material_density;
  f.cavity = post::cavity_fractions(f.grid, into_cavity, s.depth);
  if (s.method == "exact") {
    post::bin_exact(grains, f.grid, f.solid);
    f.corrected = post::correct_for_walls(f.grid, f.solid, f.cavity, s.min_cavity);
  } else if (s.method == "gaussian") {
    const double width = s.width_m > 0 ? s.width_m : s.voxel_m;
    post::bin_gaussian(grains, f.grid, width, f.solid);
    // Kernel method: the smoothed solid over the identically smoothed cavity indicator.
    const std::vector<double> smoothed_cavity = post::smooth_gaussian(f.grid, f.cavity, width);
    f.corrected = post::correct_for_walls(f.grid, f.solid, smoothed_cavity, s.min_cavity);
  } else {
    throw diefill::InputError("density", "method", "'" + s.method + "' is not a binning method", "Use exact or gaussian");
  }
  f.metadata["die_sha256"] = die.sha256;
  f.metadata["grains"] = std::to_string(grains.size());
  f.metadata["method"] = s.method;
  const post::Vec3 axis((box.lo.x() + box.hi.x()) / 2, (box.lo.y() + box.hi.y()) / 2, 0);
  r.stats = post::statistics(f, axis, std::max(4, std::min(f.grid.nz, 40)));
  return r;
}

nlohmann::json statistics_json(const post::FieldStatistics& st) {
  nlohmann::json percentiles;
  for (const auto& [p, v] : st.percentiles) percentiles[fmt::format("p{}", p)] = v;
  nlohmann::json profiles;
  for (const post::Profile& p : st.profiles)
    profiles[p.axis] = {{"position_m", p.position}, {"solid_fraction", p.solid_fraction}, {"cavity_volume_m3", p.cavity_volume}};
  return {{"mass_kg", st.mass_kg},
          {"solid_volume_m3", st.solid_volume_m3},
          {"cavity_volume_m3", st.cavity_volume_m3},
          {"fill_ratio", st.fill_ratio},
          {"solid_fraction_mean", st.mean},
          {"solid_fraction_std", st.std},
          {"solid_fraction_cv", st.cv},
          {"solid_fraction_min", st.min},
          {"solid_fraction_max", st.max},
          {"solid_fraction_percentiles", percentiles},
          {"voxels", st.voxels},
          {"merged_voxels", st.merged_voxels},
          {"profiles", profiles}};
}

void write_density(const DensityResult& r, const fs::path& dir) {
  post::write_vdb(r.field, dir / "density.vdb");
  post::write_vti(r.field, dir / "density.vti");
  post::write_plot_data(r.field, r.stats, dir / "plot_data.json");
  draw_pictures({"density", dir.string()});
}

}  // namespace app
