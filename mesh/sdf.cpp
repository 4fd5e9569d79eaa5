// The only translation unit of the mesh module that includes OpenVDB.
#include "mesh/sdf.hpp"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/ChangeBackground.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tree/LeafManager.h>

#include <fmt/core.h>

#include <cmath>
#include <mutex>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "mesh/openvdb_adapter.hpp"
#include "mesh/versions.hpp"

namespace mesh {

namespace {

using detail::initialise_openvdb;
using detail::TriMeshAdapter;

}  // namespace

struct SdfGrid::Impl {
  openvdb::FloatGrid::Ptr grid;
  openvdb::Int32Grid::Ptr closest;  // index of the closest triangle, per band voxel
  std::map<std::string, std::string> metadata;
  // A copy of the distance grid named "sdf", with the metadata, the voxel size and the units.
  openvdb::GridBase::Ptr named_distance(const std::map<std::string, std::string>& meta, double voxel) const;
};

SdfGrid::SdfGrid() : impl_(std::make_unique<Impl>()) {}
SdfGrid::~SdfGrid() = default;
SdfGrid::SdfGrid(SdfGrid&&) noexcept = default;
SdfGrid& SdfGrid::operator=(SdfGrid&&) noexcept = default;

double SdfGrid::voxel_size() const { return impl_->grid->voxelSize()[0]; }
double SdfGrid::background() const { return impl_->grid->background(); }
std::size_t SdfGrid::active_voxels() const { return impl_->grid->activeVoxelCount(); }
std::size_t SdfGrid::memory_bytes() const { return impl_->grid->memUsage(); }

geometry::Box SdfGrid::active_bounds() const {
  geometry::Box box;
  const openvdb::CoordBBox b = impl_->grid->evalActiveVoxelBoundingBox();
  const double h = voxel_size();
  box.extend(geometry::Vec3(b.min().x(), b.min().y(), b.min().z()) * h);
  box.extend(geometry::Vec3(b.max().x(), b.max().y(), b.max().z()) * h);
  return box;
}

float SdfGrid::voxel_value(int i, int j, int k) const {
  return impl_->grid->getConstAccessor().getValue(openvdb::Coord(i, j, k));
}

double SdfGrid::sample(const geometry::Vec3& p) const {
  const geometry::Vec3 x = p / voxel_size();
  const Eigen::Vector3d lower = x.array().floor();
  const geometry::Vec3 f = x - lower;
  const int i = int(lower.x()), j = int(lower.y()), k = int(lower.z());
  auto acc = impl_->grid->getConstAccessor();
  double value = 0.0;
  for (int c = 0; c < 8; ++c) {
    const int di = c >> 2 & 1, dj = c >> 1 & 1, dk = c & 1;
    const double w = (di ? f.x() : 1 - f.x()) * (dj ? f.y() : 1 - f.y()) * (dk ? f.z() : 1 - f.z());
    value += w * acc.getValue(openvdb::Coord(i + di, j + dj, k + dk));
  }
  return value;
}

bool SdfGrid::in_band(const geometry::Vec3& p) const {
  const geometry::Vec3 x = (p / voxel_size()).array().floor();
  auto acc = impl_->grid->getConstAccessor();
  for (int c = 0; c < 8; ++c)
    if (!acc.isValueOn(openvdb::Coord(int(x.x()) + (c >> 2 & 1), int(x.y()) + (c >> 1 & 1),
                                      int(x.z()) + (c & 1))))
      return false;
  return true;
}

std::vector<geometry::Vec3> SdfGrid::active_voxel_positions(std::size_t stride) const {
  std::vector<geometry::Vec3> out;
  const double h = voxel_size();
  std::size_t n = 0;
  for (auto it = impl_->grid->cbeginValueOn(); it; ++it) {
    if (!it.isVoxelValue()) continue;
    if (n++ % stride) continue;
    const openvdb::Coord c = it.getCoord();
    out.emplace_back(c.x() * h, c.y() * h, c.z() * h);
  }
  return out;
}

std::vector<SdfLeaf> SdfGrid::leaves() const {
  std::vector<SdfLeaf> out;
  out.reserve(impl_->grid->tree().leafCount());
  for (auto leaf = impl_->grid->tree().cbeginLeaf(); leaf; ++leaf) {
    SdfLeaf& l = out.emplace_back();
    const openvdb::Coord o = leaf->origin();
    l.origin = {o.x(), o.y(), o.z()};
    for (openvdb::Index n = 0; n < 512; ++n) {
      l.values[n] = leaf->getValue(n);
      l.active[n] = leaf->isValueOn(n);
    }
  }
  return out;
}

geometry::WallField SdfGrid::wall_field(const geometry::TriMesh& solid) const {
  geometry::WallField w;
  w.set_surface(solid);
  w.voxel = voxel_size();
  auto band = [&](const char* key) {
    auto it = impl_->metadata.find(key);
    return it != impl_->metadata.end() ? float(std::stod(it->second)) : float(background());
  };
  w.free_band = band("exterior_band_m");
  w.solid_band = band("interior_band_m");
  // Voxels of a leaf outside the band hold the background: clamp them to the side's band.
  const float free_band = w.free_band, solid_band = w.solid_band;
  const auto& tree = impl_->grid->tree();
  const openvdb::CoordBBox box = impl_->grid->evalActiveVoxelBoundingBox();
  for (int d = 0; d < 3; ++d) {
    w.brick_min[std::size_t(d)] = box.min()[d] >> 3;
    w.brick_count[std::size_t(d)] = (box.max()[d] >> 3) - (box.min()[d] >> 3) + 1;
  }
  const std::size_t cells = std::size_t(w.brick_count[0]) * std::size_t(w.brick_count[1]) *
                            std::size_t(w.brick_count[2]);
  w.brick_of_cell.assign(cells, -1);
  // Cells without a leaf lie wholly inside or outside: the tiles' sign says which.
  auto acc = impl_->grid->getConstAccessor();
  auto cell_of = [&](const openvdb::Coord& origin) {
    return (std::size_t((origin.x() >> 3) - w.brick_min[0]) * std::size_t(w.brick_count[1]) +
            std::size_t((origin.y() >> 3) - w.brick_min[1])) *
               std::size_t(w.brick_count[2]) +
           std::size_t((origin.z() >> 3) - w.brick_min[2]);
  };
  for (int i = 0; i < w.brick_count[0]; ++i)
    for (int j = 0; j < w.brick_count[1]; ++j)
      for (int k = 0; k < w.brick_count[2]; ++k) {
        const openvdb::Coord origin((w.brick_min[0] + i) * 8, (w.brick_min[1] + j) * 8,
                                    (w.brick_min[2] + k) * 8);
        if (acc.getValue(origin) < 0) w.brick_of_cell[cell_of(origin)] = -2;
      }
  auto closest_acc = impl_->closest->getConstAccessor();
  const std::size_t leaves = tree.leafCount();
  w.distance.reserve(leaves * 512);
  w.closest.reserve(leaves * 512);
  std::int32_t brick = 0;
  for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf, ++brick) {
    w.brick_of_cell[cell_of(leaf->origin())] = brick;
    const auto* index_leaf = closest_acc.probeConstLeaf(leaf->origin());
    for (openvdb::Index n = 0; n < 512; ++n) {
      const float v = leaf->getValue(n);
      w.distance.push_back(leaf->isValueOn(n) ? v : (v < 0 ? -solid_band : free_band));
      const bool in_band = leaf->isValueOn(n) && index_leaf && index_leaf->isValueOn(n);
      w.closest.push_back(in_band ? index_leaf->getValue(n) : -1);
    }
  }
  return w;
}

const std::map<std::string, std::string>& SdfGrid::metadata() const { return impl_->metadata; }

void SdfGrid::set_metadata(const std::string& key, const std::string& value) {
  impl_->metadata[key] = value;
}

namespace {

void write_grids(const std::filesystem::path& path, const openvdb::GridPtrVec& grids) {
  diefill::PendingFile pending(path);
  try {
    openvdb::io::File file(pending.path().string());
    file.write(grids);
    file.close();
  } catch (const openvdb::Exception& e) {
    throw diefill::InputError(path.string(), "", std::string("cannot be written: ") + e.what(), "Check the output folder");
  }
  pending.commit();
}

}  // namespace

openvdb::GridBase::Ptr SdfGrid::Impl::named_distance(const std::map<std::string, std::string>& metadata, double voxel) const {
  openvdb::FloatGrid::Ptr copy = grid->deepCopy();
  copy->setName("sdf");
  for (const auto& [key, value] : metadata) copy->insertMeta(key, openvdb::StringMetadata(value));
  copy->insertMeta("units", openvdb::StringMetadata("m"));
  copy->insertMeta("voxel_size_m", openvdb::DoubleMetadata(voxel));
  return copy;
}

void SdfGrid::write(const std::filesystem::path& path) const {
  initialise_openvdb();
  write_grids(path, {impl_->named_distance(impl_->metadata, voxel_size())});
}

void SdfGrid::write_cache(const std::filesystem::path& path) const {
  initialise_openvdb();
  openvdb::Int32Grid::Ptr closest = impl_->closest->deepCopy();
  closest->setName("closest_triangle");
  write_grids(path, {impl_->named_distance(impl_->metadata, voxel_size()), closest});
}

SdfGrid SdfGrid::read_cache(const std::filesystem::path& path) {
  initialise_openvdb();
  SdfGrid out;
  try {
    openvdb::io::File file(path.string());
    file.open();
    openvdb::GridBase::Ptr base = file.readGrid("sdf");
    out.impl_->grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
    out.impl_->closest = openvdb::gridPtrCast<openvdb::Int32Grid>(file.readGrid("closest_triangle"));
    file.close();
  } catch (const openvdb::Exception& e) {
    throw diefill::InputError(path.string(), "sdf", std::string("not a readable SDF grid: ") + e.what(),
                              "Rebuild it with `diefill sdf`");
  }
  if (!out.impl_->grid || !out.impl_->closest)
    throw diefill::InputError(path.string(), "sdf", "the grid is not a float grid",
                              "Rebuild it with `diefill sdf`");
  for (auto it = out.impl_->grid->beginMeta(); it != out.impl_->grid->endMeta(); ++it)
    if (it->second->typeName() == openvdb::StringMetadata::staticTypeName())
      out.impl_->metadata[it->first] = it->second->str();
  return out;
}

namespace {

// OpenVDB's band values are not all exact: on the bundled disc 0.08 % of the band voxels were
// off by up to 0.63 voxel, some with the wrong sign next to the tessellated wall. Every band
// voxel is therefore recomputed from the closest triangles of its 3x3x3 neighbourhood, each
// descended to the exact closest point and signed by the angle-weighted pseudo-normal; a second
// pass lets a correct closest triangle spread to neighbours that had none.
void make_band_exact(openvdb::FloatGrid& grid, openvdb::Int32Grid& closest, const geometry::TriMesh& solid,
                     const SdfGrid& sdf) {
  for (int pass = 0; pass < 2; ++pass) {
    const geometry::WallField field = sdf.wall_field(solid);
    const double h = field.voxel;
    openvdb::tree::LeafManager<openvdb::FloatTree> leaves(grid.tree());
    leaves.foreach ([&](openvdb::FloatTree::LeafNodeType& leaf, std::size_t) {
      auto* index_leaf = closest.tree().probeLeaf(leaf.origin());
      for (auto it = leaf.beginValueOn(); it; ++it) {
        const openvdb::Coord c = it.getCoord();
        geometry::SurfacePoint best;
        if (!field.nearest(geometry::Vec3(c.x() * h, c.y() * h, c.z() * h), 1, best)) continue;
        it.setValue(float(best.distance));
        if (index_leaf) index_leaf->setValueOnly(it.pos(), best.triangle);
      }
    });
  }
}

}  // namespace

SdfGrid build_sdf(const geometry::TriMesh& solid, const SdfOptions& options) {
  initialise_openvdb();
  const double h = options.voxel_m;
  auto transform = openvdb::math::Transform::createLinearTransform(h);
  TriMeshAdapter adapter{solid, 1.0 / h};
  // Our solids cross nowhere (repair's contract), so OpenVDB's removal of "self-intersecting"
  // voxels has nothing to remove and only errs: beside free space thinner than a voxel it
  // deactivated band voxels 0.03 voxel from the wall, and the flood fill then signed them from
  // across the wall (the toothed pulley: 1,007 of 10^5 points against its own solid; docs/MESHES.md,
  // "Shared test meshes").
  const int flags = openvdb::tools::DISABLE_RENORMALIZATION | openvdb::tools::DISABLE_INTERSECTING_VOXEL_REMOVAL;
  SdfGrid out;
  out.impl_->closest = openvdb::Int32Grid::create(-1);
  out.impl_->closest->setTransform(transform);
  // OpenVDB signs by inside/outside of the closed mesh, whatever its orientation: for an
  // inside-out mesh its exterior is the solid side.
  const double vdb_exterior = options.inside_out ? options.interior_band_m : options.exterior_band_m;
  const double vdb_interior = options.inside_out ? options.exterior_band_m : options.interior_band_m;
  out.impl_->grid = openvdb::tools::meshToVolume<openvdb::FloatGrid>(
      adapter, *transform, float(vdb_exterior / h), float(vdb_interior / h), flags, out.impl_->closest.get());
  out.impl_->grid->setGridClass(openvdb::GRID_LEVEL_SET);
  out.impl_->grid->setName("sdf");
  out.impl_->metadata["exterior_band_m"] = fmt::format("{:.17g}", options.exterior_band_m);
  out.impl_->metadata["interior_band_m"] = fmt::format("{:.17g}", options.interior_band_m);
  // The index grid must cover every band voxel for the candidate lookup.
  out.impl_->closest->tree().topologyUnion(out.impl_->grid->tree());
  make_band_exact(*out.impl_->grid, *out.impl_->closest, solid, out);
  // The exact band carries the sign of the mesh's orientation; the tiles beyond it follow, at
  // a background no smaller than either band (OpenVDB's is its exterior band).
  openvdb::tools::signedFloodFill(out.impl_->grid->tree());
  openvdb::tools::changeLevelSetBackground(out.impl_->grid->tree(),
                                           float(std::max(options.exterior_band_m, options.interior_band_m)));
  return out;
}

}  // namespace mesh

namespace mesh {
std::string openvdb_version() { return openvdb::getLibraryVersionString(); }
geometry::WallField contact_wall_field(const geometry::TriMesh& solid, double grain_radius) {
  const double voxel = 0.5 * grain_radius;
  return build_sdf(solid, {voxel, 1.5 * grain_radius + voxel, 2 * voxel, false}).wall_field(solid);
}

}  // namespace mesh
