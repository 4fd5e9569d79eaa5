// `diefill sdf`: the mesh stage on its own, with a readable mesh report and an optional
// verification against the exact (Embree) distance.
#include <fmt/core.h>

#include "cli/commands.hpp"
#include "core/error.hpp"
#include "mesh/die.hpp"
#include "mesh/verify.hpp"

namespace cli {

int run_sdf(const SdfCommand& c) {
  const double mm = 1e-3;
  mesh::DieOptions options = mesh::die_options_for_grains(
      c.grain_radius_mm * mm, c.skin_mm * mm,
      c.voxel_mm ? std::optional<double>(*c.voxel_mm * mm) : std::nullopt);
  options.role = mesh::parse_role(c.role, "--role");
  options.up = mesh::parse_up(c.up, "--up");
  if (c.tolerance_mm) options.repair.tolerance_m = *c.tolerance_mm * mm;
  if (c.max_hole_mm) options.repair.max_hole_m = *c.max_hole_mm * mm;
  options.table_margin_m = c.table_margin_mm * mm;

  options.parting = mesh::parse_parting(c.parting, "--parting");
  const mesh::DieFile file = mesh::read_die_file(c.mesh, geometry::parse_unit_or_auto(c.units, "--units"),
                                                 mesh::up_to_read(options), mesh::parting_to_read(options), c.part);
  options.unit = file.unit;
  const mesh::PreparedDie die = mesh::prepare_die(file, options, std::nullopt);
  fmt::print("mesh {} ({} units{}: {})\n", die.source, geometry::unit_name(options.unit),
             file.unit_guessed ? ", guessed from its size; --units chooses" : "", die.sha256);
  if (file.part > 0)
    fmt::print("part {} of the file's {} bodies (pieces that share no vertex), numbered by enclosed volume, largest first (--part)\n",
               file.part, file.bodies);
  else if (file.bodies > 1)
    fmt::print("the file holds {} bodies (pieces that share no vertex), taken as one part; --part N takes the N-th largest alone\n",
               file.bodies);
  if (die.up != mesh::Up{})
    fmt::print("orientation: the opening faces {} in the file ({}); turned so that it faces +z\n", mesh::up_name(die.up),
               !die.up_found ? "--up"
               : die.parting_z ? "found: no flat face at any extreme, so laid flat, up along the axis of its largest outline; --up chooses"
                               : "found: the flat extreme face that opens the most of its outline; --up chooses");
  fmt::print("check:\n{}", mesh::format_report(die.before));
  if (die.actions.empty()) {
    fmt::print("repair: nothing to do\n");
  } else {
    fmt::print("repair:\n");
    for (const std::string& a : die.actions) fmt::print("  - {}\n", a);
    fmt::print("  existing surface moved by at most {:.4g} mm (tolerance {:.4g} mm); new surface "
               "spans gaps up to {:.4g} mm\n",
               die.hausdorff_m / mm, options.repair.tolerance_m / mm, die.bridged_m / mm);
    fmt::print("after repair:\n{}", mesh::format_report(die.after));
  }
  fmt::print("sdf: role {}, voxel {:.4g} mm, band {:.4g} mm outside / {:.4g} mm inside, "
             "{} active voxels, {:.1f} MiB\n",
             mesh::role_name(options.role), options.voxel_m / mm, options.exterior_band_m / mm,
             options.interior_band_m / mm, die.sdf.active_voxels(),
             double(die.sdf.memory_bytes()) / (1 << 20));
  if (c.verify > 0) {
    const mesh::ExactSurface exact(die.solid);
    const geometry::WallField field = die.sdf.wall_field(die.solid);
    const mesh::SdfVerification v = mesh::verify_sdf(field, die.solid, exact, c.verify, c.seed);
    fmt::print("verify: {} points in the band (seed {}), {} farther than a voxel from a sharp "
               "edge, {} with |exact| > 0.5 voxel, {} outside or within a voxel inside (where grain centres go)\n",
               v.samples, c.seed, v.smooth_samples, v.sign_checked, v.reachable_samples);
    auto show = [&](const char* what, const mesh::SdfErrors& e) {
      fmt::print("  {}: |SDF - exact| max {:.3g} voxel, mean {:.3g} voxel; away from sharp edges "
                 "max {:.3g} voxel at ({:.4f}, {:.4f}, {:.4f}) mm; sign disagreements {}\n",
                 what, e.max_voxels, e.mean_voxels, e.max_smooth_voxels,
                 e.worst_smooth_point.x() / mm, e.worst_smooth_point.y() / mm,
                 e.worst_smooth_point.z() / mm, e.sign_disagreements);
      if (e.sign_disagreements > 0)
        fmt::print("    first sign disagreement at ({:.4f}, {:.4f}, {:.4f}) mm\n", e.first_sign_disagreement.x() / mm,
                   e.first_sign_disagreement.y() / mm, e.first_sign_disagreement.z() / mm);
    };
    show("wall query (what the simulation uses; errors where grain centres go, signs everywhere)", v.query);
    show("grid, trilinear", v.grid);
    fmt::print("  beside sharp edges: {} points within two voxels of them with |exact| > 0.5 voxel; sign disagreements {}, "
               "in wall contacts {}\n",
               v.sharp_samples, v.sharp_sign_disagreements, v.sharp_contact_sign_disagreements);
    if (v.sharp_sign_disagreements + v.sharp_contact_sign_disagreements > 0)
      fmt::print("    first at ({:.4f}, {:.4f}, {:.4f}) mm\n", v.first_sharp_disagreement.x() / mm,
                 v.first_sharp_disagreement.y() / mm, v.first_sharp_disagreement.z() / mm);
  }
  if (!c.output.empty()) {
    die.sdf.write(c.output);
    fmt::print("wrote {}\n", c.output.string());
  }
  return 0;
}

}  // namespace cli
