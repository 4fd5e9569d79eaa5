// The only translation unit of the postprocess module that includes OpenVDB.
#include <fmt/core.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <array>
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

namespace {

// A field's grids under names with `prefix`; the cavity's voxels only are active.
void add_grids(const DensityField& f, const std::string& prefix, openvdb::GridPtrVec& grids) {
  const auto& phi = f.corrected.solid_fraction;
  const std::size_t first = grids.size();
  grids.push_back(grid_of(f, prefix + "solid_fraction", [&](std::size_t n) { return phi[n]; }));
  grids.push_back(grid_of(f, prefix + "density", [&](std::size_t n) { return phi[n] * f.material_density; }));
  grids.push_back(grid_of(f, prefix + "cavity_fraction", [&](std::size_t n) { return f.cavity[n]; }));
  if (prefix.empty())  // the smoothed field's kernel spans the wall: it merges (almost) nothing
    grids.push_back(grid_of(f, "merged", [&](std::size_t n) { return double(f.corrected.merged[n]); }));
  if (!f.solid_fraction_stderr.empty())
    grids.push_back(grid_of(f, prefix + "solid_fraction_stderr", [&](std::size_t n) { return f.solid_fraction_stderr[n]; }));
  for (std::size_t g = first; g < grids.size(); ++g) {
    for (const auto& [key, value] : f.metadata) grids[g]->insertMeta(key, openvdb::StringMetadata(value));
    grids[g]->insertMeta("units", openvdb::StringMetadata("m"));
    grids[g]->insertMeta("material_density", openvdb::DoubleMetadata(f.material_density));
    grids[g]->insertMeta("voxel_size_m", openvdb::DoubleMetadata(f.grid.voxel));
  }
}

void initialize_openvdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

void write_grids(const openvdb::GridPtrVec& grids, const std::filesystem::path& path) {
  diefill::PendingFile pending(path);
  openvdb::io::File file(pending.path().string());
  file.write(grids);
  file.close();
  pending.commit();
}

}  // namespace

void write_vdb(const DensityField& f, const DensityField* smoothed, const std::filesystem::path& path) {
  initialize_openvdb();
  openvdb::GridPtrVec grids;
  add_grids(f, "", grids);
  if (smoothed) add_grids(*smoothed, "smoothed_", grids);
  write_grids(grids, path);
}

std::map<std::string, StoredGrid> read_vdb(const std::filesystem::path& path) {
  initialize_openvdb();
  std::map<std::string, StoredGrid> out;
  try {
    openvdb::io::File file(path.string());
    file.open();
    const openvdb::GridPtrVecPtr grids = file.getGrids();  // kept: the loop must not outlive it
    for (const openvdb::GridBase::Ptr& base : *grids) {
      const auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
      if (!grid) continue;
      StoredGrid& stored = out[grid->getName()];
      stored.voxel_m = grid->voxelSize()[0];
      const openvdb::Vec3d first = grid->indexToWorld(openvdb::Coord(0, 0, 0));
      stored.first_centre = Vec3(first.x(), first.y(), first.z());
      for (auto meta = grid->beginMeta(); meta != grid->endMeta(); ++meta) stored.metadata[meta->first] = meta->second->str();
      for (auto on = grid->cbeginValueOn(); on; ++on) {
        const openvdb::Coord c = on.getCoord();
        stored.values[{c.x(), c.y(), c.z()}] = double(*on);
      }
    }
    file.close();
  } catch (const openvdb::Exception& e) {
    throw diefill::InputError(path.string(), "", std::string("cannot be read as OpenVDB: ") + e.what(),
                              "Give the density.vdb a diefill run wrote");
  }
  return out;
}

void write_vdb(const std::map<std::string, StoredGrid>& grids, const std::filesystem::path& path) {
  initialize_openvdb();
  openvdb::GridPtrVec out;
  for (const auto& [name, stored] : grids) {
    auto grid = openvdb::FloatGrid::create(0.0f);
    grid->setName(name);
    auto t = openvdb::math::Transform::createLinearTransform(stored.voxel_m);
    t->postTranslate(openvdb::Vec3d(stored.first_centre.x(), stored.first_centre.y(), stored.first_centre.z()));
    grid->setTransform(t);
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    auto acc = grid->getAccessor();
    for (const auto& [index, value] : stored.values) acc.setValue(openvdb::Coord(index[0], index[1], index[2]), float(value));
    for (const auto& [key, value] : stored.metadata) grid->insertMeta(key, openvdb::StringMetadata(value));
    out.push_back(grid);
  }
  write_grids(out, path);
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
  array("merged", [&](std::size_t n) { return double(f.corrected.merged[n]); });
  if (!f.solid_fraction_stderr.empty()) array("solid_fraction_stderr", [&](std::size_t n) { return f.solid_fraction_stderr[n]; });
  out += "</CellData>\n</Piece>\n</ImageData>\n</VTKFile>\n";
  diefill::write_file_atomic(path, out);
}

namespace {

double value_or_blank(const DensityField& f, std::size_t n) {
  const double phi = f.corrected.solid_fraction[n];
  return f.cavity[n] > 0 && std::isfinite(phi) ? phi : -1.0;
}

// The voxel row through the field's centre: across the shoe's path (x fixed) or along it (y
// fixed); the grid puts a voxel centre on the die's axis (grid_covering), so no interpolation.
nlohmann::json section(const DensityField& f, bool along) {
  const VoxelGrid& g = f.grid;
  const int axis = along ? 1 : 0;
  const int at = std::clamp(int(std::lround((f.centre[axis] - g.origin[axis]) / g.voxel - 0.5)), 0, (along ? g.ny : g.nx) - 1);
  const int across = along ? g.nx : g.ny;
  nlohmann::json values = nlohmann::json::array(), merged = nlohmann::json::array(), cavity = nlohmann::json::array();
  for (int u = 0; u < across; ++u) {
    nlohmann::json column = nlohmann::json::array(), flags = nlohmann::json::array(), fractions = nlohmann::json::array();
    for (int k = 0; k < g.nz; ++k) {
      const std::size_t n = along ? g.index(u, at, k) : g.index(at, u, k);
      column.push_back(value_or_blank(f, n));
      flags.push_back(int(f.corrected.merged[n]));
      fractions.push_back(f.cavity[n]);
    }
    values.push_back(column), merged.push_back(flags), cavity.push_back(fractions);
  }
  const int u_axis = along ? 0 : 1;
  return {{"at_m", g.origin[axis] + (at + 0.5) * g.voxel},
          {"extent_m", {g.origin[u_axis], g.origin[u_axis] + across * g.voxel, g.origin.z(), g.origin.z() + g.nz * g.voxel}},
          {"values", values},
          {"merged", merged},
          {"cavity_fraction", cavity}};
}

nlohmann::json sections(const DensityField& f) { return {{"along", section(f, true)}, {"across", section(f, false)}}; }

// The top view: each column's mean (the fill an x-ray would see, with the wall's slivers
// carrying their merged values, as in the sections), whether most of its cavity holds merged
// voxels, and, for an ensemble, its standard error.
void top_view(const DensityField& f, nlohmann::json& j) {
  const VoxelGrid& g = f.grid;
  const std::vector<double> means = column_means(f);
  nlohmann::json top = nlohmann::json::array(), merged = nlohmann::json::array(), cavity = nlohmann::json::array(),
                 error = nlohmann::json::array();
  for (int i = 0; i < g.nx; ++i) {
    nlohmann::json row = nlohmann::json::array(), flags = nlohmann::json::array(), column_cavity = nlohmann::json::array(),
                   column_error = nlohmann::json::array();
    for (int jj = 0; jj < g.ny; ++jj) {
      double weight = 0, merged_weight = 0;
      for (int k = 0; k < g.nz; ++k) {
        const std::size_t n = g.index(i, jj, k);
        if (f.cavity[n] <= 0 || !std::isfinite(f.corrected.solid_fraction[n])) continue;
        weight += f.cavity[n];
        if (f.corrected.merged[n]) merged_weight += f.cavity[n];
      }
      const std::size_t column = std::size_t(i) * std::size_t(g.ny) + std::size_t(jj);
      row.push_back(means[column]);
      flags.push_back(int(weight > 0 && merged_weight > 0.5 * weight));
      column_cavity.push_back(weight);
      if (!f.column_stderr.empty()) column_error.push_back(means[column] >= 0 ? f.column_stderr[column] : -1.0);
    }
    top.push_back(row), merged.push_back(flags), cavity.push_back(column_cavity), error.push_back(column_error);
  }
  j["top_view"] = top;
  j["top_merged"] = merged;
  j["top_cavity_voxels"] = cavity;
  if (!f.column_stderr.empty()) {
    j["top_stderr"] = error;
    j["stderr_marked_fraction"] = stderr_marked_fraction;
  }
}

// The colour scale from the cavity's own values: the 1st to the 99th cavity-weighted percentile
// of the voxels the wall correction kept whole (merged slivers and empty corners would stretch it).
std::array<double, 2> colour_range(const DensityField& f) {
  std::vector<std::pair<double, double>> samples;
  double total = 0;
  for (std::size_t n = 0; n < f.grid.size(); ++n)
    if (f.cavity[n] > 0 && !f.corrected.merged[n] && std::isfinite(f.corrected.solid_fraction[n])) {
      samples.emplace_back(f.corrected.solid_fraction[n], f.cavity[n]);
      total += f.cavity[n];
    }
  if (samples.empty()) return {0.0, 1.0};
  std::sort(samples.begin(), samples.end());
  const auto percentile = [&](double p) {
    double acc = 0;
    for (const auto& [value, weight] : samples)
      if ((acc += weight) >= p * total) return value;
    return samples.back().first;
  };
  return {percentile(0.01), percentile(0.99)};
}

nlohmann::json grid_json(const VoxelGrid& g) {
  return {{"voxel_m", g.voxel}, {"origin_m", {g.origin.x(), g.origin.y(), g.origin.z()}}, {"shape", {g.nx, g.ny, g.nz}}};
}

}  // namespace

std::vector<double> column_means(const DensityField& f) {
  const VoxelGrid& g = f.grid;
  std::vector<double> out(std::size_t(g.nx) * std::size_t(g.ny), -1.0);
  for (int i = 0; i < g.nx; ++i)
    for (int j = 0; j < g.ny; ++j) {
      double sum = 0, weight = 0;
      for (int k = 0; k < g.nz; ++k) {
        const std::size_t n = g.index(i, j, k);
        const double phi = f.corrected.solid_fraction[n];
        if (f.cavity[n] <= 0 || !std::isfinite(phi)) continue;
        sum += f.cavity[n] * phi, weight += f.cavity[n];
      }
      if (weight > 0) out[std::size_t(i) * std::size_t(g.ny) + std::size_t(j)] = sum / weight;
    }
  return out;
}

namespace {
nlohmann::json profiles_json(const FieldStatistics& st) {
  nlohmann::json j;
  for (const Profile& p : st.profiles)
    j[p.axis] = {{"position_m", p.position}, {"solid_fraction", p.solid_fraction}, {"spread", p.spread}};
  return j;
}
}  // namespace

void write_plot_data(const DensityField& f, const FieldStatistics& st, const DensityField* smoothed,
                     const FieldStatistics* smoothed_stats, const Outlines& outlines, const std::filesystem::path& path) {
  const VoxelGrid& g = f.grid;
  nlohmann::json j = grid_json(g);
  j["centre_m"] = {f.centre.x(), f.centre.y()};
  j["material_density"] = f.material_density;
  j["colour_range"] = colour_range(f);
  top_view(f, j);
  j["sections"] = sections(f);
  if (smoothed) {
    j["smoothed"] = grid_json(smoothed->grid);
    j["smoothed"]["sections"] = sections(*smoothed);
    j["smoothed"]["width_m"] = std::stod(smoothed->metadata.at("width_m"));
    if (smoothed_stats) j["smoothed"]["profiles"] = profiles_json(*smoothed_stats);
  }
  j["outline"] = {{"top", outlines.top}, {"along", outlines.along}, {"across", outlines.across}};
  nlohmann::json values = nlohmann::json::array(), weights = nlohmann::json::array();
  for (std::size_t n = 0; n < g.size(); ++n)
    if (f.cavity[n] > 0 && std::isfinite(f.corrected.solid_fraction[n])) {
      values.push_back(f.corrected.solid_fraction[n]);
      weights.push_back(f.cavity[n]);
    }
  j["histogram_values"] = values;
  j["histogram_weights"] = weights;
  j["mean"] = st.mean;
  j["profiles"] = profiles_json(st);
  diefill::write_file_atomic(path, j.dump());
}

}  // namespace post
