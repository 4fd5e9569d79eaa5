#include "pipeline/compare.hpp"

#include <fmt/core.h>

#include <array>
#include <climits>
#include <cmath>
#include <fstream>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "pipeline/pictures.hpp"
#include "postprocess/field.hpp"

namespace pipeline {

namespace fs = std::filesystem;

namespace {

const char* const what_a_run_is = "Give a folder a diefill run wrote: OUT/<die name>/, with report.json and density.vdb";

// A run's report, with the keys the comparison reads (a report of an older diefill may lack some).
nlohmann::json read_report(const fs::path& run) {
  const fs::path file = run / "report.json";
  std::ifstream in(file);
  if (!in) throw diefill::InputError(run.string(), "report.json", "is missing: not a run's folder", what_a_run_is);
  nlohmann::json report;
  try {
    report = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw diefill::InputError(file.string(), "", std::string("is not JSON: ") + e.what(), what_a_run_is);
  }
  for (const char* key : {"/die/sha256", "/die/name", "/run/seed", "/run/scene_sha256", "/fill/fill_ratio", "/fill/mass_kg",
                          "/fill/solid_fraction_mean", "/fill/solid_fraction_std", "/fill/regions", "/fill/profiles"})
    if (!report.contains(nlohmann::json::json_pointer(key)))
      throw diefill::InputError(file.string(), key, "is missing (a report of an older diefill, or of a run with an empty cavity)",
                                "Run the die again with this version");
  return report;
}

std::map<std::string, post::StoredGrid> read_fields(const fs::path& run) {
  if (!fs::exists(run / "density.vdb"))
    throw diefill::InputError(run.string(), "density.vdb", "is missing (no grain reached the cavity?)", what_a_run_is);
  return post::read_vdb(run / "density.vdb");
}

const post::StoredGrid& grid_named(const std::map<std::string, post::StoredGrid>& grids, const std::string& name,
                                   const fs::path& run) {
  const auto it = grids.find(name);
  if (it == grids.end())
    throw diefill::InputError((run / "density.vdb").string(), name, "is missing", "Give the density.vdb a diefill run wrote");
  return it->second;
}

// B - A of one field on the voxels both hold, weighted by A's cavity fraction (the same die), and
// its statistics: the mean and RMS difference and the largest one.
struct Difference {
  post::StoredGrid grid;
  nlohmann::json statistics;
};

Difference difference(const std::map<std::string, post::StoredGrid>& a, const std::map<std::string, post::StoredGrid>& b,
                      const std::string& prefix, const fs::path& run_a, const fs::path& run_b) {
  const post::StoredGrid& phi_a = grid_named(a, prefix + "solid_fraction", run_a);
  const post::StoredGrid& phi_b = grid_named(b, prefix + "solid_fraction", run_b);
  const post::StoredGrid& cavity = grid_named(a, prefix + "cavity_fraction", run_a);
  if (std::abs(phi_a.voxel_m - phi_b.voxel_m) > 1e-9 * phi_a.voxel_m ||
      (phi_a.first_centre - phi_b.first_centre).norm() > 1e-6 * phi_a.voxel_m)
    throw diefill::InputError((run_b / "density.vdb").string(), prefix + "solid_fraction",
                              fmt::format("lies on another grid than {}'s ({:.4g} mm voxels against {:.4g} mm)", run_a.string(),
                                          phi_b.voxel_m * 1e3, phi_a.voxel_m * 1e3),
                              prefix.empty() ? "Compare runs of the same die with the same density.voxel"
                                             : "Compare runs of the same die with the same density.smoothed_width");
  Difference d;
  d.grid.voxel_m = phi_a.voxel_m;
  d.grid.first_centre = phi_a.first_centre;
  d.grid.metadata = {{"units", "m"}, {"meaning", "solid fraction of B minus A"}};
  double weight = 0, sum = 0, squares = 0, largest = 0;
  for (const auto& [index, value_a] : phi_a.values) {
    const auto other = phi_b.values.find(index);
    const auto c = cavity.values.find(index);
    if (other == phi_b.values.end() || c == cavity.values.end() || c->second <= 0) continue;
    const double delta = other->second - value_a;
    d.grid.values[index] = delta;
    weight += c->second, sum += c->second * delta, squares += c->second * delta * delta;
    largest = std::max(largest, std::abs(delta));
  }
  d.statistics = {{"voxels", d.grid.values.size()},
                  {"voxel_m", d.grid.voxel_m},
                  {"mean_difference", weight > 0 ? sum / weight : 0.0},
                  {"rms_difference", weight > 0 ? std::sqrt(squares / weight) : 0.0},
                  {"largest_difference", largest}};
  return d;
}

// The report values of the comparison: A, B and B - A.
nlohmann::json side_by_side(const nlohmann::json& a, const nlohmann::json& b) {
  nlohmann::json out;
  for (const char* key : {"fill_ratio", "mass_kg", "solid_fraction_mean", "solid_fraction_std"})
    out[key] = {{"a", a["fill"][key]}, {"b", b["fill"][key]}, {"difference", b["fill"][key].get<double>() - a["fill"][key].get<double>()}};
  for (const auto& [region, values] : a["fill"]["regions"].items()) {
    const double ra = values["fill_ratio"], rb = b["fill"]["regions"][region]["fill_ratio"];
    out["regions"][region] = {{"a", ra}, {"b", rb}, {"difference", rb - ra}};
  }
  return out;
}

// The difference's top view (each column's cavity-weighted mean, as the runs' own top views;
// -2 where the column is empty) and both runs' profiles, for plots.py.
nlohmann::json plot_data(const post::StoredGrid& diff, const post::StoredGrid& cavity, const nlohmann::json& a,
                         const nlohmann::json& b) {
  nlohmann::json out = {{"profiles", {{"a", a["fill"]["profiles"]}, {"b", b["fill"]["profiles"]}}},
                        {"labels", {a["run"]["label"], b["run"]["label"]}}};
  if (diff.values.empty()) return out;
  std::array<int, 3> lo{INT_MAX, INT_MAX, INT_MAX}, hi{INT_MIN, INT_MIN, INT_MIN};
  for (const auto& [index, value] : diff.values)
    for (int axis = 0; axis < 3; ++axis) lo[axis] = std::min(lo[axis], index[axis]), hi[axis] = std::max(hi[axis], index[axis]);
  const int nx = hi[0] - lo[0] + 1, ny = hi[1] - lo[1] + 1;
  std::vector<std::vector<double>> sum(std::size_t(nx), std::vector<double>(std::size_t(ny), 0.0)), count = sum;
  for (const auto& [index, value] : diff.values) {
    const double weight = cavity.values.at(index);  // difference() keeps voxels with cavity only
    sum[std::size_t(index[0] - lo[0])][std::size_t(index[1] - lo[1])] += weight * value;
    count[std::size_t(index[0] - lo[0])][std::size_t(index[1] - lo[1])] += weight;
  }
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j) {
      double& s = sum[std::size_t(i)][std::size_t(j)];
      const double n = count[std::size_t(i)][std::size_t(j)];
      s = n > 0 ? s / n : -2.0;
    }
  const double h = diff.voxel_m;
  out["top_difference"] = sum;
  out["extent_m"] = {diff.first_centre.x() + (lo[0] - 0.5) * h, diff.first_centre.x() + (hi[0] + 0.5) * h,
                     diff.first_centre.y() + (lo[1] - 0.5) * h, diff.first_centre.y() + (hi[1] + 0.5) * h};
  return out;
}

}  // namespace

nlohmann::json compare_runs(const fs::path& run_a, const fs::path& run_b, const fs::path& out) {
  nlohmann::json a = read_report(run_a), b = read_report(run_b);
  if (a["die"]["sha256"] != b["die"]["sha256"])
    throw diefill::InputError(run_b.string(), "die.sha256", fmt::format("is another die than {}'s", run_a.string()),
                              "Compare two runs of the same die file");
  const auto fields_a = read_fields(run_a), fields_b = read_fields(run_b);
  const Difference exact = difference(fields_a, fields_b, "", run_a, run_b);
  nlohmann::json summary = {{"a", run_a.string()},
                            {"b", run_b.string()},
                            {"die", a["die"]["name"]},
                            {"same_scene", a["run"]["scene_sha256"] == b["run"]["scene_sha256"]},
                            {"seeds", {a["run"]["seed"], b["run"]["seed"]}},
                            {"fill", side_by_side(a, b)},
                            {"field", exact.statistics}};
  std::map<std::string, post::StoredGrid> grids = {{"solid_fraction_difference", exact.grid}};
  if (fields_a.count("smoothed_solid_fraction") && fields_b.count("smoothed_solid_fraction")) {
    Difference smoothed = difference(fields_a, fields_b, "smoothed_", run_a, run_b);
    summary["smoothed_field"] = smoothed.statistics;
    grids.emplace("smoothed_solid_fraction_difference", std::move(smoothed.grid));
  }
  a["run"]["label"] = fmt::format("A: {} (seed {})", run_a.string(), a["run"]["seed"].get<std::uint64_t>());
  b["run"]["label"] = fmt::format("B: {} (seed {})", run_b.string(), b["run"]["seed"].get<std::uint64_t>());
  diefill::StagingFolder staged(out);
  diefill::write_file_atomic(staged / "compare.json", summary.dump(2) + "\n");
  post::write_vdb(grids, staged / "difference.vdb");
  diefill::write_file_atomic(staged / "compare_plot.json", plot_data(exact.grid, fields_a.at("cavity_fraction"), a, b).dump());
  draw_pictures({"compare", staged.path().string()});
  staged.commit();
  return summary;
}

}  // namespace pipeline
