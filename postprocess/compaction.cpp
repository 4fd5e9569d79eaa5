#include "postprocess/compaction.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "core/atomic_file.hpp"
#include "core/error.hpp"

namespace post {

namespace fs = std::filesystem;

namespace {

constexpr double table_step = 0.05;  // of solid fraction, from one step up to 1

std::string deck(const FemFill& f, double travel, const CompactionSettings& s) {
  // fill.inp holds the deck's one *HEADING.
  std::string out = "** diefill's worked compaction example: linear elastic, E tabulated against the solid fraction.\n";
  out += "** Units SI. The solid fraction is each node's temperature (fill_calculix.inp); no *EXPANSION.\n";
  out += "*INCLUDE, INPUT=fill.inp\n*MATERIAL, NAME=POWDER\n*DEPVAR\n2\n*ELASTIC\n";
  for (int k = 1; k * table_step <= 1.0 + 1e-12; ++k) {
    const double phi = k * table_step;
    out += fmt::format("{:.9g}, {:.9g}, {:.9g}\n", s.solid_youngs_modulus * std::pow(phi, s.modulus_exponent), s.poisson_ratio, phi);
  }
  out += fmt::format("*DENSITY\n{:.9g}\n", f.material_density);
  out += "*SOLID SECTION, ELSET=CAVITY, MATERIAL=POWDER\n*INCLUDE, INPUT=fill_calculix.inp\n";
  out += "*STEP\n*STATIC\n*BOUNDARY\nTABLE, 1, 2\nFLOOR, 1, 2\nWALLS, 1, 2\nFLOOR, 3, 3\n";
  out += fmt::format("TABLE, 3, 3, {:.12g}\n", -travel);
  out += "*NODE PRINT, NSET=TABLE, TOTALS=ONLY\nRF\n*NODE PRINT, NSET=ALL_NODES\nU\n*EL PRINT, ELSET=CAVITY\nS\n*END STEP\n";
  return out;
}

// The rows of a .dat block whose title starts with `title`, up to the next title.
std::vector<std::vector<double>> block(const std::string& dat, const std::string& title) {
  std::vector<std::vector<double>> rows;
  std::istringstream in(dat);
  std::string line;
  bool inside = false;
  while (std::getline(in, line)) {
    if (line.find(" for set ") != std::string::npos) {
      inside = line.find(title) != std::string::npos;
      continue;
    }
    if (!inside) continue;
    std::istringstream fields(line);
    std::vector<double> row;
    for (double v; fields >> v;) row.push_back(v);
    if (!row.empty()) rows.push_back(row);
  }
  return rows;
}

}  // namespace

double tabulated_modulus(const CompactionSettings& s, double phi) {
  const double clamped = std::clamp(phi, table_step, 1.0);
  const int k = std::min(int(std::floor(clamped / table_step)), int(std::round(1.0 / table_step)) - 1);
  const double lo = k * table_step, hi = (k + 1) * table_step;
  const double e_lo = s.solid_youngs_modulus * std::pow(lo, s.modulus_exponent);
  const double e_hi = s.solid_youngs_modulus * std::pow(hi, s.modulus_exponent);
  return e_lo + (e_hi - e_lo) * (clamped - lo) / (hi - lo);
}

double constrained_modulus(double e, double nu) { return e * (1 - nu) / ((1 + nu) * (1 - 2 * nu)); }

CompactionResult run_compaction(const FemFill& f, const fs::path& dir, const CompactionSettings& s) {
  double floor_z = f.mesh.nodes.front().z(), table_z = floor_z;
  for (const Vec3& p : f.mesh.nodes) floor_z = std::min(floor_z, p.z()), table_z = std::max(table_z, p.z());
  if (boundary_sets(f.mesh, table_z).table.empty())
    throw diefill::InputError((dir / "fill.inp").string(), "TABLE",
                              "no boundary face of the mesh lies in its top plane, so the punch would press nothing",
                              "Check that the die's cavity has its flat opening on the table");
  CompactionResult r;
  r.punch_travel_m = s.axial_strain * (table_z - floor_z);
  diefill::write_file_atomic(dir / "compaction.inp", deck(f, r.punch_travel_m, s));
  if (std::system("command -v ccx >/dev/null 2>&1") != 0)
    throw diefill::InputError((dir / "compaction.inp").string(), "ccx", "CalculiX (ccx) is not installed",
                              "Install it (scripts/setup.sh does: Debian package calculix-ccx), or run the deck elsewhere");
  const fs::path log = dir / "ccx.log";
  const std::string command = fmt::format("cd '{}' && OMP_NUM_THREADS=1 ccx -i compaction > ccx.log 2>&1", dir.string());
  const int status = std::system(command.c_str());
  std::ifstream log_in(log);
  r.log.assign(std::istreambuf_iterator<char>(log_in), {});
  std::ifstream dat_in(dir / "compaction.dat");
  const std::string dat(std::istreambuf_iterator<char>(dat_in), {});
  const auto force = block(dat, "total force");
  if (status != 0 || force.empty() || r.log.find("*ERROR") != std::string::npos)
    throw diefill::InputError(log.string(), "ccx", "CalculiX failed on the compaction deck", "Read its log");
  r.punch_force_n = -force.front().at(2);
  for (const auto& row : block(dat, "displacements")) {
    const std::size_t node = std::size_t(row.at(0)) - 1;
    if (r.node_displacement.size() <= node) r.node_displacement.resize(node + 1, Vec3::Zero());
    r.node_displacement[node] = Vec3(row.at(1), row.at(2), row.at(3));
  }
  std::vector<int> points(f.mesh.tets.size(), 0);
  r.element_axial_stress.assign(f.mesh.tets.size(), 0.0);
  for (const auto& row : block(dat, "stresses")) {
    const std::size_t e = std::size_t(row.at(0)) - 1;
    r.element_axial_stress.at(e) += row.at(4);
    ++points[e];
  }
  for (std::size_t e = 0; e < points.size(); ++e)
    if (points[e] > 0) r.element_axial_stress[e] /= points[e];
  return r;
}

}  // namespace post
