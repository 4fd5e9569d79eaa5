#include "pipeline/density_stage.hpp"

#include <fmt/core.h>


#include "core/error.hpp"
#include "core/log.hpp"
#include "mesh/exact.hpp"
#include "pipeline/pictures.hpp"
#include "postprocess/ensemble_stats.hpp"

namespace pipeline {

namespace fs = std::filesystem;

namespace {

// The cavity's box: the free side of the tool below the table (or the inside of a container),
// and the die's axis, which the sections pass through.
struct CavityBox {
  post::Vec3 lo, hi, centre;
  bool container = false;
};

CavityBox cavity_box(const mesh::PreparedDie& die) {
  CavityBox c;
  c.container = die.sdf.metadata().count("role") && die.sdf.metadata().at("role") == "container";
  const geometry::Box box = die.after.bbox;
  c.lo = box.lo;
  c.hi = post::Vec3(box.hi.x(), box.hi.y(), c.container ? box.hi.z() : die.table_z);
  c.centre = post::Vec3(0.5 * (c.lo.x() + c.hi.x()), 0.5 * (c.lo.y() + c.hi.y()), c.hi.z());
  return c;
}

// The grains binned on voxels of edge `voxel` and corrected for the walls: exactly, or by the
// Gaussian kernel of `width` over the identically smoothed cavity (the kernel method).
post::DensityField binned_field(const std::vector<post::Grain>& grains, const CavityBox& c,
                                const geometry::WallField& walls, double voxel,
                                scene::DensityMethod method, double width, const DensityOptions& s) {
  post::DensityField f;
  const post::Vec3 reach = post::Vec3::Constant(method == scene::DensityMethod::gaussian ? 3 * width : 0.0);  // every kernel whole
  f.grid = post::grid_covering(c.lo - reach, c.hi + reach, voxel,
                               post::Vec3(c.centre.x(), c.centre.y(), c.container ? c.lo.z() : c.hi.z()));
  f.centre = c.centre;
  f.min_cavity = s.min_cavity;
  // The cavity lies within its bounding box. Bounding by the box matters where the grid reaches
  // past the die's field (coarse voxels below a thin table): there the field reads "free".
  const post::CavityVolumes cavity =
      post::cavity_fractions(f.grid, [&](const post::Vec3& p) { return walls.signed_distance(p); }, c.lo, c.hi, s.depth);
  f.cavity = cavity.fraction;
  if (method == scene::DensityMethod::exact) {
    post::bin_exact(grains, f.grid, f.solid);
    f.corrected = post::correct_for_walls(f.grid, f.solid, f.cavity, s.min_cavity);
  } else {
    post::bin_gaussian(grains, f.grid, width, f.solid);
    const std::vector<double> smoothed_cavity = post::smooth_gaussian(f.grid, cavity, width);
    f.corrected = post::correct_for_walls(f.grid, f.solid, smoothed_cavity, s.min_cavity);
    f.metadata["width_m"] = fmt::format("{:.9g}", width);
  }
  f.metadata["method"] = std::string(diefill::choice_name(scene::density_methods, method));
  return f;
}

post::Outlines outlines_of(const geometry::TriMesh& cavity, const CavityBox& c, double voxel) {
  const double below_opening = c.hi.z() - 0.25 * std::min(voxel, c.hi.z() - c.lo.z());
  return {geometry::plane_section(cavity, 2, below_opening), geometry::plane_section(cavity, 1, c.centre.y()),
          geometry::plane_section(cavity, 0, c.centre.x())};
}

}  // namespace

std::vector<post::Region> fill_regions(const post::VoxelGrid& g, const post::Vec3& centre, double floor_z, double table_z,
                                       double grain_diameter, const std::function<double(const post::Vec3&)>& distance_to_wall) {
  std::vector<post::Region> regions = {{"near_wall", {}}, {"core", {}}, {"leading_half", {}}, {"trailing_half", {}}, {"bottom_quarter", {}}};
  for (post::Region& r : regions) r.share.assign(g.size(), 0.0);
  const double bottom = floor_z + 0.25 * (table_z - floor_z);
  for (int i = 0; i < g.nx; ++i)
    for (int j = 0; j < g.ny; ++j)
      for (int k = 0; k < g.nz; ++k) {
        const std::size_t n = g.index(i, j, k);
        const post::Vec3 p = g.centre(i, j, k);
        const bool near = distance_to_wall(p) < grain_diameter;
        regions[0].share[n] = near, regions[1].share[n] = !near;
        const double side = (p.x() - centre.x()) / g.voxel;  // the voxel row on the centre: half each
        regions[2].share[n] = side < -1e-6 ? 1.0 : side > 1e-6 ? 0.0 : 0.5;
        regions[3].share[n] = 1.0 - regions[2].share[n];
        regions[4].share[n] = p.z() < bottom;
      }
  return regions;
}

DensityResult compute_density(const std::vector<post::Grain>& grains, const mesh::PreparedDie& die,
                              const geometry::WallField& walls, double material_density, const DensityOptions& s,
                              const std::string& particles_source) {
  if (!(s.voxel_m > 0)) throw diefill::InputError("density", "voxel", "must be positive", "Give the voxel edge");
  const CavityBox c = cavity_box(die);
  std::size_t in_box = 0;
  double largest_radius = 0;
  for (const post::Grain& g : grains) {
    in_box += (g.centre.array() >= c.lo.array()).all() && (g.centre.array() <= c.hi.array()).all();
    largest_radius = std::max(largest_radius, g.radius);
  }
  if (in_box == 0)
    throw diefill::InputError(particles_source, "positions",
                              fmt::format("none of its {} grains lies in the cavity of {} ({:.3g} to {:.3g} mm)",
                                          grains.size(), die.source, c.lo.minCoeff() * 1e3, c.hi.maxCoeff() * 1e3),
                              "Give the die the grains were simulated in, with the same units");

  DensityResult r;
  const double width = s.width_m > 0 ? s.width_m : s.voxel_m;
  r.field = binned_field(grains, c, walls, s.voxel_m, s.method, width, s);
  r.field.material_density = material_density;
  r.field.metadata["die_sha256"] = die.sha256;
  r.field.metadata["grains"] = std::to_string(grains.size());
  r.field.metadata["die"] = die.name;
  r.field.metadata["coarse_graining"] = fmt::format("{}", s.coarse_graining);
  r.stats = post::statistics(r.field);
  if (s.smoothed_width_m > 0) {
    r.smoothed = binned_field(grains, c, walls, s.smoothed_width_m, scene::DensityMethod::gaussian, s.smoothed_width_m, s);
    r.smoothed->material_density = material_density;
    r.smoothed->metadata.insert(r.field.metadata.begin(), r.field.metadata.end());  // the rest: the same grains
    r.smoothed_stats = post::statistics(*r.smoothed);
  }
  // Regions as thin as a grain need voxels finer than one: the smoothed field's, binned exactly.
  const post::DensityField& fine = r.smoothed ? *r.smoothed : r.field;
  std::vector<double> fine_solid;
  post::bin_exact(grains, fine.grid, fine_solid);
  // The wall field's distance saturates a little beyond a grain radius; Embree's is exact.
  const mesh::ExactSurface tool(die.solid);
  const auto distance_to_wall = [&](const post::Vec3& p) { return walls.signed_distance(p) < 0 ? -1.0 : tool.distance(p); };
  r.stats.regions = post::region_statistics(fine.grid, fine_solid, fine.cavity,
                                            fill_regions(fine.grid, c.centre, c.lo.z(), c.hi.z(), 2 * largest_radius, distance_to_wall));
  r.outlines = outlines_of(die.cavity, c, s.voxel_m);
  return r;
}

namespace {

post::DensityField mean_field(const std::vector<const post::DensityField*>& seeds) {
  post::DensityField mean = *seeds.front();
  std::vector<std::vector<double>> solids, fractions, columns;
  for (const post::DensityField* f : seeds) {
    if (f->grid.size() != mean.grid.size() || f->grid.voxel != mean.grid.voxel || f->cavity != mean.cavity)
      throw std::logic_error("a seed ensemble's fields lie on different grids or cavities");
    solids.push_back(f->solid);
    fractions.push_back(f->corrected.solid_fraction);
    columns.push_back(post::column_means(*f));
  }
  mean.solid = post::mean_and_error(solids).mean;
  post::MeanAndError phi = post::mean_and_error(fractions);
  mean.corrected.solid_fraction = std::move(phi.mean);
  mean.solid_fraction_stderr = std::move(phi.error);
  mean.column_stderr = post::mean_and_error(columns).error;
  return mean;
}

}  // namespace

DensityResult mean_density(const std::vector<DensityResult>& seeds) {
  std::vector<const post::DensityField*> fields, smoothed;
  for (const DensityResult& r : seeds) {
    fields.push_back(&r.field);
    if (r.smoothed) smoothed.push_back(&*r.smoothed);
  }
  DensityResult mean;
  mean.field = mean_field(fields);
  mean.stats = post::statistics(mean.field);
  mean.stats.regions = seeds.front().stats.regions;
  for (std::size_t k = 0; k < mean.stats.regions.size(); ++k) {
    double sum = 0;
    for (const DensityResult& r : seeds) sum += r.stats.regions[k].fill_ratio;
    mean.stats.regions[k].fill_ratio = sum / double(seeds.size());
  }
  if (smoothed.size() == seeds.size()) {
    mean.smoothed = mean_field(smoothed);
    mean.smoothed_stats = post::statistics(*mean.smoothed);
  }
  mean.outlines = seeds.front().outlines;
  return mean;
}

nlohmann::json statistics_json(const post::FieldStatistics& st) {
  nlohmann::json percentiles;
  for (const auto& [p, v] : st.percentiles) percentiles[fmt::format("p{}", p)] = v;
  nlohmann::json profiles;
  for (const post::Profile& p : st.profiles)
    profiles[p.axis] = {{"position_m", p.position},
                        {"solid_fraction", p.solid_fraction},
                        {"spread", p.spread},
                        {"cavity_volume_m3", p.cavity_volume}};
  nlohmann::json regions;
  for (const post::RegionStatistics& g : st.regions)
    regions[g.name] = {{"fill_ratio", g.fill_ratio}, {"cavity_volume_m3", g.cavity_volume_m3}};
  return {{"mass_kg", st.mass_kg},
          {"solid_volume_m3", st.solid_volume_m3},
          {"cavity_volume_m3", st.cavity_volume_m3},
          {"fill_ratio", st.fill_ratio},
          {"apparent_density_kg_m3", st.cavity_volume_m3 > 0 ? st.mass_kg / st.cavity_volume_m3 : 0.0},
          {"apparent_density_g_cm3", st.cavity_volume_m3 > 0 ? st.mass_kg / st.cavity_volume_m3 * 1e-3 : 0.0},
          {"solid_fraction_mean", st.mean},
          {"solid_fraction_std", st.std},
          {"solid_fraction_cv", st.cv},
          {"solid_fraction_min", st.min},
          {"solid_fraction_max", st.max},
          {"solid_fraction_percentiles", percentiles},
          {"voxels", st.voxels},
          {"merged_voxels", st.merged_voxels},
          {"profiles", profiles},
          {"regions", regions}};
}

void write_density(const DensityResult& r, const fs::path& dir, bool pictures) {
  const post::DensityField* smoothed = r.smoothed ? &*r.smoothed : nullptr;
  post::write_vdb(r.field, smoothed, dir / "density.vdb");
  post::write_vti(r.field, dir / "density.vti");
  if (smoothed) post::write_vti(*smoothed, dir / "density_smoothed.vti");
  post::write_plot_data(r.field, r.stats, smoothed, smoothed ? &r.smoothed_stats : nullptr, r.outlines, dir / "plot_data.json");
  if (pictures) draw_pictures({"density", dir.string()});
}

}  // namespace pipeline
