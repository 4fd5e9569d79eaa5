#include "mesh/die.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numeric>
#include <nlohmann/json.hpp>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "core/sha256.hpp"
#include "core/timer.hpp"
#include "mesh/cgal_ops.hpp"
#include "mesh/source_hash.hpp"

namespace mesh {

namespace fs = std::filesystem;
using diefill::InputError;
using nlohmann::json;

namespace {

// Cache entries name the hash of the mesh module's sources (generated at build time): any
// change to the code that builds them invalidates them.
constexpr const char* cache_format = DIEFILL_MESH_SOURCE_HASH;

json report_json(const MeshReport& r) {
  return {{"triangles", r.triangles},
          {"vertices", r.vertices},
          {"boundary_edges", r.boundary_edges},
          {"non_manifold_edges", r.non_manifold_edges},
          {"inconsistent_edges", r.inconsistent_edges},
          {"degenerate_faces", r.degenerate_faces},
          {"duplicate_faces", r.duplicate_faces},
          {"self_intersections", r.self_intersections},
          {"shells", r.shells},
          {"closed", r.closed},
          {"orientation", r.orientation},
          {"volume_m3", r.volume_m3},
          {"area_m2", r.area_m2},
          {"bbox_min_m", {r.bbox.lo.x(), r.bbox.lo.y(), r.bbox.lo.z()}},
          {"bbox_max_m", {r.bbox.hi.x(), r.bbox.hi.y(), r.bbox.hi.z()}}};
}

MeshReport report_from_json(const json& j) {
  MeshReport r;
  r.triangles = j.at("triangles");
  r.vertices = j.at("vertices");
  r.boundary_edges = j.at("boundary_edges");
  r.non_manifold_edges = j.at("non_manifold_edges");
  r.inconsistent_edges = j.at("inconsistent_edges");
  r.degenerate_faces = j.at("degenerate_faces");
  r.duplicate_faces = j.at("duplicate_faces");
  r.self_intersections = j.at("self_intersections");
  r.shells = j.at("shells");
  r.closed = j.at("closed");
  r.orientation = j.at("orientation");
  r.volume_m3 = j.at("volume_m3");
  r.area_m2 = j.at("area_m2");
  for (int d = 0; d < 3; ++d) {
    r.bbox.lo[d] = j.at("bbox_min_m")[d];
    r.bbox.hi[d] = j.at("bbox_max_m")[d];
  }
  return r;
}

// Meshes in the cache are raw doubles and int32 indices: exact, and fast to read back.
void write_mesh_binary(const geometry::TriMesh& m, const fs::path& path) {
  std::string bytes;
  const std::uint64_t nv = m.vertices.size(), nt = m.triangles.size();
  bytes.append(reinterpret_cast<const char*>(&nv), 8);
  bytes.append(reinterpret_cast<const char*>(&nt), 8);
  for (const geometry::Vec3& v : m.vertices) bytes.append(reinterpret_cast<const char*>(v.data()), 24);
  for (const geometry::Triangle& t : m.triangles) bytes.append(reinterpret_cast<const char*>(t.data()), 12);
  diefill::write_file_atomic(path, bytes);
}

std::optional<geometry::TriMesh> read_mesh_binary(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::uint64_t nv = 0, nt = 0;
  if (!in.read(reinterpret_cast<char*>(&nv), 8) || !in.read(reinterpret_cast<char*>(&nt), 8))
    return std::nullopt;
  geometry::TriMesh m;
  m.vertices.resize(nv);
  m.triangles.resize(nt);
  for (geometry::Vec3& v : m.vertices) in.read(reinterpret_cast<char*>(v.data()), 24);
  for (geometry::Triangle& t : m.triangles) in.read(reinterpret_cast<char*>(t.data()), 12);
  if (!in) return std::nullopt;
  return m;
}

void check_options(const DieOptions& o, const std::string& source) {
  auto positive = [&](double v, const char* field) {
    if (!(v > 0) || !std::isfinite(v))
      throw InputError(source, field, fmt::format("must be a positive length, got {}", v),
                       "Give a positive value");
  };
  positive(o.voxel_m, "voxel");
  positive(o.exterior_band_m, "exterior band");
  positive(o.interior_band_m, "interior band");
  positive(o.repair.tolerance_m, "tolerance");
  positive(o.table_margin_m, "table margin");
}

// The part below the parting plane becomes the cavity: the table cuts it at its widest section
// and the upper punch would form the rest (docs/INTERFACE.md, `die.parting`).
void cut_at_parting_plane(PreparedDie& die, const std::string& source) {
  const geometry::Box whole = geometry::bounding_box(die.cavity);
  const double z = *die.parting_z;
  geometry::TriMesh below;
  if (!detail::clip_below(die.cavity, z, below))
    throw InputError(source, "die.parting",
                     fmt::format("cutting the part at its widest section, z = {:.4g} mm, did not leave a closed solid",
                                 z * 1e3),
                     "Give the die's cavity with its flat opening (the part's face on the die table)");
  die.actions.push_back(fmt::format(
      "the die table cuts the part at its widest section, {:.4g} mm above its lowest point of its {:.4g} mm height: "
      "the cavity is the part below, the upper punch would form the rest (die.parting)",
      (z - whole.lo.z()) * 1e3, whole.size().z() * 1e3));
  die.cavity = std::move(below);
  die.after = inspect(die.cavity);
}

// The `part`-th largest of an assembly's bodies by enclosed volume (1: the largest; ties in the
// file's order). A die forms one part; an assembly's parts stand apart by clearances no die wall
// is as thin as (docs/MESHES.md, "Assemblies").
geometry::TriMesh body_of_assembly(std::vector<geometry::TriMesh> bodies, int part, const std::string& source) {
  std::vector<double> volume(bodies.size());
  std::transform(bodies.begin(), bodies.end(), volume.begin(), [](const geometry::TriMesh& b) { return std::abs(geometry::signed_volume(b)); });
  std::vector<std::size_t> largest_first(bodies.size());
  std::iota(largest_first.begin(), largest_first.end(), 0);
  std::stable_sort(largest_first.begin(), largest_first.end(), [&](std::size_t a, std::size_t b) { return volume[a] > volume[b]; });
  if (part >= 1 && std::size_t(part) <= bodies.size()) return std::move(bodies[largest_first[std::size_t(part) - 1]]);
  std::string largest;
  for (std::size_t k = 0; k < std::min<std::size_t>(5, bodies.size()); ++k) {
    const geometry::Box box = geometry::bounding_box(bodies[largest_first[k]]);
    const geometry::Vec3 size = 1e3 * box.size(), at = 1e3 * box.lo;
    largest += fmt::format("{}{}: {:.4g} mm³, {:.3g} x {:.3g} x {:.3g} mm from ({:.4g}, {:.4g}, {:.4g})", k ? "; " : "", k + 1,
                           volume[largest_first[k]] * 1e9, size.x(), size.y(), size.z(), at.x(), at.y(), at.z());
  }
  throw InputError(source, "part",
                   fmt::format("part {} was asked for, and the file holds {} separate bodies (the largest: {})", part,
                               bodies.size(), largest),
                   fmt::format("Choose a part from 1 to {} (die.part, diefill sdf --part), numbered by volume, largest "
                               "first, or 0 for the whole file",
                               bodies.size()));
}

}  // namespace

WallRole parse_role(std::string_view text, std::string_view field) {
  if (text == "solid") return WallRole::tool;
  if (const auto role = diefill::find_choice(wall_roles, text)) return *role;
  throw InputError("", std::string(field), "unknown role '" + std::string(text) + "'",
                   "Use cavity (the part's shape, open at the table), tool (the die body) or "
                   "container (a closed vessel holding the grains)");
}


DieOptions die_options_for_grains(double grain_radius_m, double skin_m, std::optional<double> voxel_m) {
  DieOptions o;
  o.voxel_m = voxel_m ? *voxel_m : default_voxel_fraction * grain_radius_m;
  o.exterior_band_m = grain_radius_m + skin_m + o.voxel_m;
  // Three voxels inside, as OpenVDB's level sets keep: a trilinear sample 1.5 voxels inside reads
  // corners up to half a cell diagonal deeper (2.4 voxels), beyond a band of two.
  o.interior_band_m = 3.0 * o.voxel_m;
  o.repair.tolerance_m = 0.5 * o.voxel_m;
  o.repair.max_hole_m = 10.0 * o.voxel_m;
  // A gap narrower than a voxel the field cannot show, and none narrower than a grain admits one.
  o.repair.closable_gap_m = std::min(o.voxel_m, 2.0 * grain_radius_m);
  return o;
}

std::string die_cache_key(const DieFile& file, std::optional<double> parting_z, const DieOptions& o) {
  std::string text = fmt::format(
      "format={};sha={};unit={};up={};role={};voxel={:.17g};ext={:.17g};int={:.17g};tol={:.17g};"
      "hole={:.17g};gap={:.17g};wrap={};margin={:.17g}",
      cache_format, file.sha256, geometry::unit_name(o.unit), up_name(file.up), role_name(o.role), o.voxel_m, o.exterior_band_m,
      o.interior_band_m, o.repair.tolerance_m, o.repair.max_hole_m, o.repair.closable_gap_m, o.repair.allow_wrap,
      o.table_margin_m);
  if (parting_z) text += fmt::format(";parting={:.17g}", *parting_z);
  if (file.part > 0) text += fmt::format(";part={}", file.part);
  if (o.table)
    text += fmt::format(";table={:.17g},{:.17g},{:.17g},{:.17g},{:.17g}", o.table->x_min,
                        o.table->y_min, o.table->x_max, o.table->y_max, o.table->thickness);
  return diefill::sha256_hex(text);
}

DieFile read_die_file(const fs::path& path, std::optional<geometry::LengthUnit> unit, std::optional<Up> up, Parting parting, int part) {
  DieFile file;
  file.source = path.string();
  file.name = path.stem().string();
  // Import first: it gives the clear message for a missing, empty or unreadable file.
  ImportResult imported = import_mesh(path, {unit});
  file.unit = imported.unit;
  file.unit_guessed = imported.unit_guessed;
  // The unit is the file's, guessed from all of it; the opening is the part's own.
  std::vector<geometry::TriMesh> bodies = geometry::separate_bodies(imported.mesh);
  file.bodies = bodies.size();
  file.part = part;
  file.mesh = part == 0 ? std::move(imported.mesh) : body_of_assembly(std::move(bodies), part, file.source);
  file.sha256 = diefill::sha256_file(path);
  file.up_found = !up;
  const bool opens = up ? opening_area(file.mesh, *up) > 0 : has_flat_extreme(file.mesh);
  const bool cut = parting == Parting::widest || (parting == Parting::automatic && !opens);
  file.up = up ? *up : (cut && !opens) ? lying_flat(file.mesh) : find_opening(file.mesh, file.source);
  turn_up(file.mesh, file.up);
  if (cut) file.parting_z = widest_section_z(file.mesh);
  return file;
}

std::optional<Up> up_to_read(const DieOptions& options) {
  return options.up || options.role == WallRole::cavity ? options.up : Up{};
}

Parting parting_to_read(const DieOptions& options) {
  return options.role == WallRole::cavity ? options.parting : Parting::opening;
}

PreparedDie prepare_die(const fs::path& path, const DieOptions& options, const std::optional<fs::path>& cache_dir) {
  return prepare_die(read_die_file(path, options.unit, up_to_read(options), parting_to_read(options)), options, cache_dir);
}

PreparedDie prepare_die(const DieFile& file, const DieOptions& options, const std::optional<fs::path>& cache_dir) {
  const std::string& source = file.source;
  check_options(options, source);
  if (file.unit != options.unit)
    throw InputError(source, "units", "the file was read in another unit than the options give", "Read it in the options' unit");
  if (options.up && *options.up != file.up)
    throw InputError(source, "up", "the file was turned another way than the options give", "Read it with the options' up");
  PreparedDie out;
  out.source = source;
  out.name = file.name;
  out.sha256 = file.sha256;
  out.up = file.up;
  out.up_found = file.up_found;
  out.parting_z = options.role == WallRole::cavity ? file.parting_z : std::nullopt;
  out.unit = file.unit;
  out.unit_guessed = file.unit_guessed;
  out.part = file.part;
  out.cache_key = die_cache_key(file, out.parting_z, options);

  if (cache_dir) {
    const fs::path base = *cache_dir / out.cache_key;
    std::ifstream meta_in(base.string() + ".json");
    if (meta_in) {
      try {
        const json meta = json::parse(meta_in);
        auto cavity = read_mesh_binary(base.string() + ".cavity.bin");
        auto solid = read_mesh_binary(base.string() + ".solid.bin");
        if (cavity && solid && meta.at("key") == out.cache_key) {
          out.before = report_from_json(meta.at("before"));
          out.after = report_from_json(meta.at("after"));
          out.actions = meta.at("actions").get<std::vector<std::string>>();
          out.wrapped = meta.at("wrapped");
          out.hausdorff_m = meta.at("hausdorff_m");
          out.bridged_m = meta.at("bridged_m");
          out.table_z = meta.at("table_z");
          out.cavity = std::move(*cavity);
          out.solid = std::move(*solid);
          out.sdf = SdfGrid::read_cache(base.string() + ".vdb");
          out.sdf_from_cache = true;
          return out;
        }
      } catch (const std::exception& e) {
        diefill::log::warn_here("ignoring a broken cache entry {}: {}", base.string(), e.what());
      }
    }
  }

  RepairOptions repair_options = options.repair;
  repair_options.free_space_inside = options.role != WallRole::tool;
  RepairResult repaired = repair(file.mesh, repair_options, source);
  out.before = repaired.before;
  out.after = repaired.after;
  out.actions = repaired.actions;
  out.wrapped = repaired.wrapped;
  out.hausdorff_m = repaired.hausdorff_m;
  out.bridged_m = repaired.bridged_m;
  out.cavity = std::move(repaired.mesh);
  if (out.parting_z) cut_at_parting_plane(out, source);

  const double extent = out.after.bbox.size().maxCoeff();
  if (extent < 4 * options.voxel_m)
    throw InputError(source, "units",
                     fmt::format("the die is only {:.4g} mm across, less than 4 voxels of {:.4g} mm "
                                 "(read as {})",
                                 extent * 1e3, options.voxel_m * 1e3, geometry::unit_name(options.unit)),
                     "If the file is in metres or inches, declare it (--units m, --units in, or "
                     "units = \"m\" in the scene); otherwise choose a smaller voxel");

  if (options.role == WallRole::cavity) {
    const TableExtent table = options.table ? *options.table : table_around(out.cavity, options.table_margin_m);
    ToolMesh tool = tool_from_cavity(out.cavity, table, source);
    out.solid = std::move(tool.mesh);
    out.table_z = tool.table_z;
  } else if (options.role == WallRole::container) {
    out.solid = out.cavity;
    for (geometry::Triangle& t : out.solid.triangles) std::swap(t[1], t[2]);
    out.table_z = out.after.bbox.lo.z();
  } else {
    out.solid = out.cavity;
    out.table_z = out.after.bbox.hi.z();
  }

  diefill::Stopwatch clock;
  out.sdf = build_sdf(out.solid, {options.voxel_m, options.exterior_band_m, options.interior_band_m,
                                  options.role == WallRole::container});
  diefill::log::debug("sdf: {} active voxels in {:.2f} s", out.sdf.active_voxels(), clock.seconds());
  out.sdf.set_metadata("role", std::string(role_name(options.role)));
  out.sdf.set_metadata("source_sha256", out.sha256);
  out.sdf.set_metadata("source", fs::path(source).filename().string());
  out.sdf.set_metadata("table_z_m", fmt::format("{:.17g}", out.table_z));

  if (cache_dir) {
    const fs::path base = *cache_dir / out.cache_key;
    write_mesh_binary(out.cavity, base.string() + ".cavity.bin");
    write_mesh_binary(out.solid, base.string() + ".solid.bin");
    out.sdf.write_cache(base.string() + ".vdb");
    // The JSON is written last: an entry counts only once all its files are complete.
    const json meta = {{"key", out.cache_key},
                       {"source", source},
                       {"before", report_json(out.before)},
                       {"after", report_json(out.after)},
                       {"actions", out.actions},
                       {"wrapped", out.wrapped},
                       {"hausdorff_m", out.hausdorff_m},
                       {"bridged_m", out.bridged_m},
                       {"table_z", out.table_z}};
    diefill::write_file_atomic(base.string() + ".json", meta.dump(2));
  }
  return out;
}

}  // namespace mesh
