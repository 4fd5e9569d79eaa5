#include "pipeline/walls.hpp"

#include <fmt/core.h>

#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "core/log.hpp"
#include "mesh/exact.hpp"
#include "mesh/shapes.hpp"
#include "pipeline/preflight.hpp"

namespace pipeline {

using dem::Vec3;

namespace {

// The die's mesh stage for grains of largest radius r: voxels a fraction of it, the table as long
// as the shoe's travel and as wide as the shoe, plus a margin.
mesh::DieOptions die_options(const scene::PipelineScene& s, const GrainSizing& grains, const ShoePlan& shoe, const DieSource& source) {
  const double r = grains.r_max;
  mesh::DieOptions o = mesh::die_options_for_grains(r, 0.5 * r, s.die.voxel_fraction * r);
  o.unit = source.file.unit;
  o.up = source.file.up;
  o.role = mesh::WallRole::cavity;
  // Room beside the shoe: grains that pass under its walls (the strike-off) stay on the table
  // rather than falling off a table the size of the shoe (two radii let one grain in 2000 off).
  const double margin = 2e-3 + 6 * r;
  o.table = mesh::TableExtent{shoe.x_start - 0.5 * shoe.length - s.shoe.wall - margin,
                              shoe.y_centre - 0.5 * shoe.width - s.shoe.wall - margin,
                              shoe.x_end + 0.5 * shoe.length + s.shoe.wall + margin,
                              shoe.y_centre + 0.5 * shoe.width + s.shoe.wall + margin, 2e-3};
  return o;
}

// A shoe from a mesh is a tool in its own frame (origin at the inner centre, on the table); the
// built-in one a rectangular tube. Voxels as mesh::contact_wall_field's: the query is exact, the
// voxels only find candidates.
std::shared_ptr<const geometry::WallField> shoe_field(const scene::PipelineScene& s, const GrainSizing& grains, const ShoePlan& shoe,
                                                      geometry::LengthUnit unit, const std::filesystem::path& cache) {
  const double r = grains.r_max;
  if (s.shoe.mesh.empty())
    return std::make_shared<const geometry::WallField>(
        mesh::contact_wall_field(mesh::shoe_solid(shoe.length, shoe.width, s.shoe.height, s.shoe.wall), r));
  mesh::DieOptions o = mesh::die_options_for_grains(r, 0.5 * r, 0.5 * r);
  o.unit = unit;
  o.role = mesh::WallRole::tool;
  const mesh::PreparedDie prepared = mesh::prepare_die(s.shoe.mesh, o, cache);
  return std::make_shared<const geometry::WallField>(prepared.sdf.wall_field(prepared.solid));
}

// Grains too coarse for the cavity: refused when none can enter it; warned when it is narrower
// than a few grains, where the wall layer is most of the part (docs/PHYSICS.md §4).
void check_grains_enter(const FillWalls& w, const DieSource& source, const GrainSizing& grains) {
  const double inscribed =
      largest_inscribed_radius_bound(*w.die_field, w.die.solid, source.box, source.table_z, 0.1 * grains.r_max);
  if (inscribed < grains.r_max)
    throw diefill::InputError(source.file.source, "powder.coarse_graining",
                              fmt::format("grains up to {:.3g} mm across cannot enter the cavity: the largest sphere it holds is "
                                          "at most {:.3g} mm across",
                                          2 * grains.r_max * 1e3, 2 * inscribed * 1e3),
                              "Lower powder.coarse_graining (or raise powder.max_grains, which coarsens grains for large shoes)");
  if (inscribed < 1.5 * grains.diameter)
    diefill::log::warn("{}: the cavity holds no sphere wider than {:.3g} mm, under three grains of {:.3g} mm: the density "
                       "there is mostly wall layer; lower powder.coarse_graining",
                       w.die.name, 2 * inscribed * 1e3, grains.diameter * 1e3);
}

// The coarse-grained laws with the die and the shoe as walls, inside the table's extent; the
// shoe's place recorded in `w`.
dem::ModelSpec fill_spec(const scene::PipelineScene& s, FillWalls& w, const DieSource& source, const GrainSizing& grains,
                         const ShoePlan& shoe, const mesh::TableExtent& table) {
  dem::ModelSpec spec = fill_laws(s, grains, source.box.size().z());
  spec.domain = {Vec3(table.x_min, table.y_min, source.box.lo.z() - 1e-3),
                 Vec3(table.x_max, table.y_max, source.table_z + s.shoe.height + 5e-3)};
  spec.meshes.push_back(dem::fixed_mesh_wall(w.die_field, w.steel, "die"));
  dem::MeshWall shoe_wall = dem::fixed_mesh_wall(w.shoe_field, w.steel, "shoe");
  shoe_wall.motion.start_position = shoe.motion.start_position;
  // Cut at the table, so that a grain pinched between the table (or the rim) and the shoe
  // overlaps them by at most half the stop limit together: the strike-off never stops a run
  // (cut at half a radius, a pinched grain reached the limit in one run in ten at 1.6 mm).
  shoe_wall.cut_z = source.table_z;
  shoe_wall.cut_fraction = 1 - 0.5 * spec.stop_overlap;
  // A pinched pair overlaps about twice as deep as the wall presses (model.hpp): at half the stop limit.
  shoe_wall.cut_cap = 0.25 * spec.stop_overlap;
  w.shoe_wall = spec.meshes.size();
  spec.meshes.push_back(shoe_wall);
  return spec;
}

}  // namespace

// The distance to the die is 1-Lipschitz, so the true maximum exceeds the sampled one by at most
// half a grid diagonal. Beyond the field's band, which reads as the band there, the exact distance.
double largest_inscribed_radius_bound(const geometry::WallField& die, const geometry::TriMesh& die_solid, const geometry::Box& cavity,
                                      double table_z, double spacing) {
  const mesh::ExactSurface exact(die_solid);
  const Vec3 size = cavity.size();
  spacing = std::max(spacing, size.maxCoeff() / 64);
  const int nx = int(size.x() / spacing) + 1, ny = int(size.y() / spacing) + 1, nz = int((table_z - cavity.lo.z()) / spacing) + 1;
  double best = -std::numeric_limits<double>::infinity();
#pragma omp parallel for collapse(2) reduction(max : best) schedule(static)
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) {
        const Vec3 p = cavity.lo + spacing * Vec3(i + 0.5, j + 0.5, k + 0.5);
        const double near = die.signed_distance(p);
        best = std::max(best, near >= die.free_band ? exact.distance(p) : near);
      }
  return best + 0.5 * std::sqrt(3.0) * spacing;
}

FillWalls prepare_walls(const scene::PipelineScene& s, const DieSource& source, const GrainSizing& grains, const ShoePlan& shoe) {
  FillWalls w;
  w.powder = scene::powder_material(s.spec);
  w.steel = scene::tool_material(s.spec);
  w.cache = s.output.cache.empty() ? s.output.directory / ".cache" : s.output.cache;
  const mesh::DieOptions options = die_options(s, grains, shoe, source);
  w.die = mesh::prepare_die(source.file, options, w.cache);
  for (const std::string& action : w.die.actions) diefill::log::info("{}: {}", source.file.name, action);
  w.die_field = std::make_shared<const geometry::WallField>(w.die.sdf.wall_field(w.die.solid));
  w.shoe_field = shoe_field(s, grains, shoe, options.unit, w.cache);
  check_grains_enter(w, source, grains);
  w.spec = fill_spec(s, w, source, grains, shoe, *options.table);
  return w;
}

}  // namespace pipeline
