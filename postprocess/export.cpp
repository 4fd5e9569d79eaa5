// The only translation unit of the postprocess module that includes OpenVDB.
#include <fmt/core.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <cmath>
#include <mutex>
#include <nlohmann/json.hpp>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "postprocess/field.hpp"

namespace post {

namespace {

// World transform: voxel (i, j, k) of the grid is OpenVDB voxel (i, j, k), centred at
// origin + h (i + 1/2, j + 1/2, k + 1/2) in metres.
openvdb::math::Transform::Ptr transform_of(const VoxelGrid& g) {
  auto t = openvdb::math::Transform::createLinearTransform(g.voxel);
  t->postTranslate(openvdb::Vec3d(g.origin.x() + 0.5 * g.voxel, g.origin.y() + 0.5 * g.voxel,
                                  g.origin.z() + 0.5 * g.voxel));
  return t;
}

openvdb::FloatGrid::Ptr grid_of(const DensityField& f, const std::string& name, const std::function<double(std::size_t)>& value) {
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName(name);
  grid->setTransform(transform_of(f.grid));
  grid->setGridClass(openvdb::GRID_FOG_VOLUME);
  auto acc = grid->getAccessor();
  for (int i = 0; i < f.grid.nx; ++i)
    for (int j = 0; j < f.grid.ny; ++j)
      for (int k = 0; k < f.grid.nz; ++k) {
        const std::size_t n = f.grid.index(i, j, k);
        if (f.cavity[n] <= 0) continue;  // only the cavity is active
        const double v = value(n);
        acc.setValue(openvdb::Coord(i, j, k), std::isfinite(v) ? float(v) : 0.0f);
      }
  return grid;
}

}  // namespace

void write_vdb(const DensityField& f, const std::filesystem::path& path) {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
  openvdb::GridPtrVec grids;
  const auto& phi = f.corrected.solid_fraction;
  grids.push_back(grid_of(f, "solid_fraction", [&](std::size_t n) { return phi[n]; }));
  grids.push_back(grid_of(f, "density", [&](std::size_t n) { return phi[n] * f.material_density; }));
  grids.push_back(grid_of(f, "cavity_fraction", [&](std::size_t n) { return f.cavity[n]; }));
  for (auto& grid : grids) {
    for (const auto& [key, value] : f.metadata) grid->insertMeta(key, openvdb::StringMetadata(value));
    grid->insertMeta("units", openvdb::StringMetadata("m"));
    grid->insertMeta("material_density", openvdb::DoubleMetadata(f.material_density));
    grid->insertMeta("voxel_size_m", openvdb::DoubleMetadata(f.grid.voxel));
  }
  diefill::PendingFile pending(path);
  openvdb::io::File file(pending.path().string());
  file.write(grids);
  file.close();
  pending.commit();
}

void write_vti(const DensityField& f, const std::filesystem::path& path) {
  const VoxelGrid& g = f.grid;
  std::string out = "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"0.1\" byte_order=\"LittleEndian\">\n";
  out += fmt::format("<ImageData WholeExtent=\"0 {} 0 {} 0 {}\" Origin=\"{:.9g} {:.9g} {:.9g}\" Spacing=\"{:.9g} {:.9g} {:.9g}\">\n",
                     g.nx, g.ny, g.nz, g.origin.x(), g.origin.y(), g.origin.z(), g.voxel, g.voxel, g.voxel);
  out += fmt::format("<Piece Extent=\"0 {} 0 {} 0 {}\">\n<CellData Scalars=\"solid_fraction\">\n", g.nx, g.ny, g.nz);
  // VTK orders cells x fastest.
  auto array = [&](const char* name, const std::function<double(std::size_t)>& value) {
    out += fmt::format("<DataArray type=\"Float32\" Name=\"{}\" format=\"ascii\">\n", name);
    for (int k = 0; k < g.nz; ++k)
      for (int j = 0; j < g.ny; ++j)
        for (int i = 0; i < g.nx; ++i) {
          const std::size_t n = g.index(i, j, k);
          const double v = f.cavity[n] > 0 ? value(n) : 0.0;
          out += fmt::format("{:.6g}\n", std::isfinite(v) ? v : 0.0);
        }
    out += "</DataArray>\n";
  };
  const auto& phi = f.corrected.solid_fraction;
  array("solid_fraction", [&](std::size_t n) { return phi[n]; });
  array("density", [&](std::size_t n) { return phi[n] * f.material_density; });
  array("cavity_fraction", [&](std::size_t n) { return f.cavity[n]; });
  out += "</CellData>\n</Piece>\n</ImageData>\n</VTKFile>\n";
  diefill::write_file_atomic(path, out);
}

void write_plot_data(const DensityField& f, const FieldStatistics& st, const std::filesystem::path& path) {
  const VoxelGrid& g = f.grid;
  nlohmann::json j;
  j["voxel_m"] = g.voxel;
  j["origin_m"] = {g.origin.x(), g.origin.y(), g.origin.z()};
  j["shape"] = {g.nx, g.ny, g.nz};
  j["material_density"] = f.material_density;
  // Top view: each column's solid volume over its cavity volume (the fill an x-ray would see).
  nlohmann::json top = nlohmann::json::array(), outline = nlohmann::json::array();
  for (int i = 0; i < g.nx; ++i) {
    nlohmann::json row = nlohmann::json::array(), cav = nlohmann::json::array();
    for (int jj = 0; jj < g.ny; ++jj) {
      double solid = 0, cavity = 0;
      for (int k = 0; k < g.nz; ++k) solid += f.solid[g.index(i, jj, k)], cavity += f.cavity[g.index(i, jj, k)];
      row.push_back(cavity > 0 ? solid / (cavity * g.voxel_volume()) : -1.0);
      cav.push_back(cavity);
    }
    top.push_back(row);
    outline.push_back(cav);
  }
  j["top_view"] = top;
  j["top_cavity_voxels"] = outline;
  // Vertical section through the middle of y.
  nlohmann::json section = nlohmann::json::array();
  const int mid = g.ny / 2;
  for (int i = 0; i < g.nx; ++i) {
    nlohmann::json col = nlohmann::json::array();
    for (int k = 0; k < g.nz; ++k) {
      const std::size_t n = g.index(i, mid, k);
      const double phi = f.corrected.solid_fraction[n];
      col.push_back(f.cavity[n] > 0 && std::isfinite(phi) ? phi : -1.0);
    }
    section.push_back(col);
  }
  j["section_y_m"] = g.origin.y() + (mid + 0.5) * g.voxel;
  j["section"] = section;
  nlohmann::json values = nlohmann::json::array(), weights = nlohmann::json::array();
  for (std::size_t n = 0; n < g.size(); ++n)
    if (f.cavity[n] > 0 && std::isfinite(f.corrected.solid_fraction[n])) {
      values.push_back(f.corrected.solid_fraction[n]);
      weights.push_back(f.cavity[n]);
    }
  j["histogram_values"] = values;
  j["histogram_weights"] = weights;
  j["mean"] = st.mean;
  for (const Profile& p : st.profiles) j["profiles"][p.axis] = {{"position_m", p.position}, {"solid_fraction", p.solid_fraction}};
  diefill::write_file_atomic(path, j.dump());
}

}  // namespace post
