// The only translation unit of the mesh module that includes OpenVDB.
#include "mesh/sdf.hpp"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>

#include <cmath>
#include <mutex>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "mesh/versions.hpp"

namespace mesh {

namespace {

void initialise_openvdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

// Points go to OpenVDB's index space in double precision, without a float copy.
struct TriMeshAdapter {
  const TriMesh& mesh;
  double inverse_voxel;
  std::size_t polygonCount() const { return mesh.triangles.size(); }
  std::size_t pointCount() const { return mesh.vertices.size(); }
  std::size_t vertexCount(std::size_t) const { return 3; }
  void getIndexSpacePoint(std::size_t n, std::size_t v, openvdb::Vec3d& pos) const {
    const Vec3& p = mesh.vertices[std::size_t(mesh.triangles[n][v])];
    pos = openvdb::Vec3d(p.x(), p.y(), p.z()) * inverse_voxel;
  }
};

}  // namespace

struct SdfGrid::Impl {
  openvdb::FloatGrid::Ptr grid;
  std::map<std::string, std::string> metadata;
};

SdfGrid::SdfGrid() : impl_(std::make_unique<Impl>()) {}
SdfGrid::~SdfGrid() = default;
SdfGrid::SdfGrid(SdfGrid&&) noexcept = default;
SdfGrid& SdfGrid::operator=(SdfGrid&&) noexcept = default;

double SdfGrid::voxel_size() const { return impl_->grid->voxelSize()[0]; }
double SdfGrid::background() const { return impl_->grid->background(); }
std::size_t SdfGrid::active_voxels() const { return impl_->grid->activeVoxelCount(); }
std::size_t SdfGrid::memory_bytes() const { return impl_->grid->memUsage(); }

Box SdfGrid::active_bounds() const {
  Box box;
  const openvdb::CoordBBox b = impl_->grid->evalActiveVoxelBoundingBox();
  const double h = voxel_size();
  box.extend(Vec3(b.min().x(), b.min().y(), b.min().z()) * h);
  box.extend(Vec3(b.max().x(), b.max().y(), b.max().z()) * h);
  return box;
}

float SdfGrid::voxel_value(int i, int j, int k) const {
  return impl_->grid->getConstAccessor().getValue(openvdb::Coord(i, j, k));
}

double SdfGrid::sample(const Vec3& p) const {
  const Vec3 x = p / voxel_size();
  const Eigen::Vector3d lower = x.array().floor();
  const Vec3 f = x - lower;
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

bool SdfGrid::in_band(const Vec3& p) const {
  const Vec3 x = (p / voxel_size()).array().floor();
  auto acc = impl_->grid->getConstAccessor();
  for (int c = 0; c < 8; ++c)
    if (!acc.isValueOn(openvdb::Coord(int(x.x()) + (c >> 2 & 1), int(x.y()) + (c >> 1 & 1),
                                      int(x.z()) + (c & 1))))
      return false;
  return true;
}

std::vector<Vec3> SdfGrid::active_voxel_positions(std::size_t stride) const {
  std::vector<Vec3> out;
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

const std::map<std::string, std::string>& SdfGrid::metadata() const { return impl_->metadata; }

void SdfGrid::set_metadata(const std::string& key, const std::string& value) {
  impl_->metadata[key] = value;
}

void SdfGrid::write(const std::filesystem::path& path) const {
  initialise_openvdb();
  openvdb::FloatGrid::Ptr grid = impl_->grid->deepCopy();
  grid->setName("sdf");
  for (const auto& [key, value] : impl_->metadata) grid->insertMeta(key, openvdb::StringMetadata(value));
  grid->insertMeta("units", openvdb::StringMetadata("m"));
  grid->insertMeta("voxel_size_m", openvdb::DoubleMetadata(voxel_size()));
  diefill::PendingFile pending(path);
  try {
    openvdb::io::File file(pending.path().string());
    file.write({grid});
    file.close();
  } catch (const openvdb::Exception& e) {
    throw diefill::InputError(path.string(), "", std::string("cannot be written: ") + e.what(),
                              "Check the output folder");
  }
  pending.commit();
}

SdfGrid SdfGrid::read(const std::filesystem::path& path) {
  initialise_openvdb();
  SdfGrid out;
  try {
    openvdb::io::File file(path.string());
    file.open();
    openvdb::GridBase::Ptr base = file.readGrid("sdf");
    file.close();
    out.impl_->grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
  } catch (const openvdb::Exception& e) {
    throw diefill::InputError(path.string(), "sdf", std::string("not a readable SDF grid: ") + e.what(),
                              "Rebuild it with `diefill sdf`");
  }
  if (!out.impl_->grid)
    throw diefill::InputError(path.string(), "sdf", "the grid is not a float grid",
                              "Rebuild it with `diefill sdf`");
  for (auto it = out.impl_->grid->beginMeta(); it != out.impl_->grid->endMeta(); ++it)
    if (it->second->typeName() == openvdb::StringMetadata::staticTypeName())
      out.impl_->metadata[it->first] = it->second->str();
  return out;
}

SdfGrid build_sdf(const TriMesh& solid, const SdfOptions& options) {
  initialise_openvdb();
  const double h = options.voxel_m;
  auto transform = openvdb::math::Transform::createLinearTransform(h);
  TriMeshAdapter adapter{solid, 1.0 / h};
  const int flags = openvdb::tools::DISABLE_RENORMALIZATION;
  SdfGrid out;
  out.impl_->grid = openvdb::tools::meshToVolume<openvdb::FloatGrid>(
      adapter, *transform, float(options.exterior_band_m / h), float(options.interior_band_m / h),
      flags);
  out.impl_->grid->setGridClass(openvdb::GRID_LEVEL_SET);
  out.impl_->grid->setName("sdf");
  return out;
}

}  // namespace mesh

namespace mesh {
std::string openvdb_version() { return openvdb::getLibraryVersionString(); }
}  // namespace mesh
