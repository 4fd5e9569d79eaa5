// The FEM hand-off's files: the Abaqus input dialect (which CalculiX reads too, but for the
// keywords each lacks: see write_fem in fem.hpp) and a VTK unstructured grid.
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "core/atomic_file.hpp"
#include "postprocess/fem.hpp"

namespace post {

namespace {

// The mesh as written: linear, or with middle nodes.
struct Elements {
  const std::vector<Vec3>* nodes;
  const std::vector<double>* node_fraction;
  std::vector<std::vector<int>> tets;
  int integration_points;  // CalculiX: 1 for C3D4, 4 for C3D10
  const char* abaqus_type;
  int vtk_type;  // 10 tetra, 24 quadratic tetra
};

Elements elements_of(const FemFill& f, const QuadraticTets* q) {
  Elements out{q ? &q->nodes : &f.mesh.nodes, q ? &q->node_fraction : &f.node_fraction, {}, q ? 4 : 1,
               q ? "C3D10" : "C3D4", q ? 24 : 10};
  if (q)
    for (const auto& t : q->tets) out.tets.emplace_back(t.begin(), t.end());
  else
    for (const auto& t : f.mesh.tets) out.tets.emplace_back(t.begin(), t.end());
  return out;
}

// Abaqus data lines hold at most 16 entries; sets are written 16 per line.
void write_set(std::string& out, const std::string& keyword, const std::vector<int>& one_based) {
  out += keyword + "\n";
  for (std::size_t i = 0; i < one_based.size(); ++i)
    out += fmt::format("{}{}", one_based[i], (i % 16 == 15 || i + 1 == one_based.size()) ? "\n" : ", ");
}

// The faces' nodes, with their edges' middle nodes for quadratic elements (1-based, sorted).
std::vector<int> nodes_of(const std::vector<std::array<int, 3>>& faces, const QuadraticTets* q) {
  std::set<int> nodes;
  for (const auto& f : faces)
    for (int k = 0; k < 3; ++k) {
      nodes.insert(f[k] + 1);
      if (q) nodes.insert(q->middle_of_edge.at(std::minmax(f[k], f[(k + 1) % 3])) + 1);
    }
  return {nodes.begin(), nodes.end()};
}

std::string mesh_deck(const FemFill& f, const Elements& el, const QuadraticTets* q, const std::string& heading,
                      double table_z) {
  std::string out = "*HEADING\n" + heading + "\n";
  out += "** Written by diefill (docs/INTERFACE.md, \"FEM hand-off\"). Units: SI (m, kg, s, Pa).\n";
  out += "** The fill's state per node and element: *INCLUDE fill_abaqus.inp (Abaqus) or fill_calculix.inp (CalculiX).\n";
  out += "*NODE, NSET=ALL_NODES\n";
  for (std::size_t n = 0; n < el.nodes->size(); ++n) {
    const Vec3& p = (*el.nodes)[n];
    out += fmt::format("{}, {:.12g}, {:.12g}, {:.12g}\n", n + 1, p.x(), p.y(), p.z());
  }
  out += fmt::format("*ELEMENT, TYPE={}, ELSET=CAVITY\n", el.abaqus_type);
  for (std::size_t e = 0; e < el.tets.size(); ++e) {
    out += fmt::format("{}", e + 1);
    for (int n : el.tets[e]) out += fmt::format(", {}", n + 1);
    out += "\n";
  }
  // One set per hundredth of solid fraction: a material per set is the way to density-dependent
  // properties in a code without field-dependent ones.
  std::map<int, std::vector<int>> bins;
  for (std::size_t e = 0; e < f.element_fraction.size(); ++e)
    bins[std::clamp(int(std::floor(f.element_fraction[e] * 100)), 0, 100)].push_back(int(e) + 1);
  for (const auto& [bin, members] : bins) write_set(out, fmt::format("*ELSET, ELSET=FILL_PHI{:03d}", bin), members);
  const BoundarySets sets = boundary_sets(f.mesh, table_z);
  write_set(out, "*NSET, NSET=TABLE", nodes_of(sets.table, q));
  write_set(out, "*NSET, NSET=FLOOR", nodes_of(sets.floor, q));
  write_set(out, "*NSET, NSET=WALLS", nodes_of(sets.walls, q));
  return out;
}

// Every node's solid fraction, as an initial condition of the given type.
std::string node_fractions(const std::string& type, const Elements& el) {
  std::string out = "*INITIAL CONDITIONS, TYPE=" + type + "\n";
  for (std::size_t n = 0; n < el.nodes->size(); ++n) out += fmt::format("{}, {:.9g}\n", n + 1, (*el.node_fraction)[n]);
  return out;
}

std::string abaqus_state(const FemFill& f, const Elements& el) {
  std::string out = "** Abaqus: the fill's solid fraction as field variable 1 at every node (a DPC or Cam-Clay model\n"
                    "** whose parameters are tabulated against it with DEPENDENCIES=1 picks it up), and per element\n"
                    "** solution-dependent state variables 1 (solid fraction) and 2 (density, kg/m^3): *DEPVAR 2.\n";
  out += node_fractions("FIELD, VARIABLE=1", el);
  out += "*INITIAL CONDITIONS, TYPE=SOLUTION\n";
  for (std::size_t e = 0; e < f.element_fraction.size(); ++e)
    out += fmt::format("{}, {:.9g}, {:.9g}\n", e + 1, f.element_fraction[e], f.element_fraction[e] * f.material_density);
  return out;
}

std::string calculix_state(const FemFill& f, const Elements& el) {
  std::string out = "** CalculiX (2.20 has no field variables): the fill's solid fraction as every node's initial\n"
                    "** temperature, for material data tabulated against temperature (give no *EXPANSION), and per\n"
                    "** element and integration point state variables 1 (solid fraction) and 2 (density, kg/m^3):\n"
                    "** the material needs *DEPVAR 2 and must come before this file.\n";
  out += node_fractions("TEMPERATURE", el);
  out += "*INITIAL CONDITIONS, TYPE=SOLUTION\n";
  for (std::size_t e = 0; e < f.element_fraction.size(); ++e)
    for (int ip = 1; ip <= el.integration_points; ++ip)
      out += fmt::format("{}, {}, {:.9g}, {:.9g}\n", e + 1, ip, f.element_fraction[e], f.element_fraction[e] * f.material_density);
  return out;
}

std::string vtu(const FemFill& f, const Elements& el) {
  std::string out = fmt::format(
      "<?xml version=\"1.0\"?>\n<!-- diefill FEM hand-off: points in metres; density in kg/m^3 -->\n"
      "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n"
      "<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n<Points>\n"
      "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n",
      el.nodes->size(), el.tets.size());
  for (const Vec3& p : *el.nodes) out += fmt::format("{:.12g} {:.12g} {:.12g}\n", p.x(), p.y(), p.z());
  out += "</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const auto& t : el.tets) {
    for (int n : t) out += fmt::format("{} ", n);
    out += "\n";
  }
  out += "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (std::size_t e = 0; e < el.tets.size(); ++e) out += fmt::format("{}\n", (e + 1) * el.tets[e].size());
  out += "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (std::size_t e = 0; e < el.tets.size(); ++e) out += fmt::format("{}\n", el.vtk_type);
  out += "</DataArray>\n</Cells>\n<CellData Scalars=\"solid_fraction\">\n";
  auto array = [&](const char* name, std::size_t count, auto value) {
    out += fmt::format("<DataArray type=\"Float64\" Name=\"{}\" format=\"ascii\">\n", name);
    for (std::size_t i = 0; i < count; ++i) out += fmt::format("{:.9g}\n", value(i));
    out += "</DataArray>\n";
  };
  const std::size_t cells = el.tets.size(), points = el.nodes->size();
  array("solid_fraction", cells, [&](std::size_t e) { return f.element_fraction[e]; });
  array("density_kg_m3", cells, [&](std::size_t e) { return f.element_fraction[e] * f.material_density; });
  array("volume_m3", cells, [&](std::size_t e) { return f.element_volume[e]; });
  if (!f.element_fraction_stderr.empty())
    array("solid_fraction_stderr", cells, [&](std::size_t e) { return f.element_fraction_stderr[e]; });
  out += "</CellData>\n<PointData Scalars=\"solid_fraction\">\n";
  array("solid_fraction", points, [&](std::size_t n) { return (*el.node_fraction)[n]; });
  array("density_kg_m3", points, [&](std::size_t n) { return (*el.node_fraction)[n] * f.material_density; });
  out += "</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  return out;
}

}  // namespace

BoundarySets boundary_sets(const geometry::TetMesh& m, double table_z) {
  std::map<std::array<int, 3>, std::array<int, 4>> faces;  // sorted face -> its face as oriented, and uses
  constexpr int opposite[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};  // outward for positive tets
  for (const geometry::Tet& t : m.tets)
    for (const auto& f : opposite) {
      std::array<int, 3> key = {t[f[0]], t[f[1]], t[f[2]]};
      std::sort(key.begin(), key.end());
      auto [it, added] = faces.emplace(key, std::array<int, 4>{t[f[0]], t[f[1]], t[f[2]], 0});
      ++it->second[3];
    }
  // Mesh_3 places the nodes of a flat face by its constructions, not exactly in its plane: on
  // the turbine blade's cut one node of the table lay 1.85 nm above the other 3,556 (1.2e-8
  // of the coordinates), which took the plane with it and left the punch no face. A millionth
  // of the coordinates' size is far beyond that and far below any feature an element resolves.
  double size = 0;
  for (const Vec3& p : m.nodes) size = std::max(size, p.cwiseAbs().maxCoeff());
  const double on_plane = 1e-6 * std::max(size, 1e-3);
  BoundarySets sets;
  for (const auto& [key, face] : faces) {
    if (face[3] != 1) continue;
    const Vec3 &a = m.nodes[face[0]], &b = m.nodes[face[1]], &c = m.nodes[face[2]];
    const Vec3 normal = (b - a).cross(c - a).normalized();
    const bool on_table = std::abs(a.z() - table_z) <= on_plane && std::abs(b.z() - table_z) <= on_plane &&
                          std::abs(c.z() - table_z) <= on_plane;
    auto& set = on_table && normal.z() > 0 ? sets.table : normal.z() < -std::sqrt(0.5) ? sets.floor : sets.walls;
    set.push_back({face[0], face[1], face[2]});
  }
  return sets;
}

std::size_t write_fem(const FemFill& f, bool quadratic_elements, const std::string& heading, const std::filesystem::path& dir) {
  double table_z = -std::numeric_limits<double>::infinity();
  for (const Vec3& p : f.mesh.nodes) table_z = std::max(table_z, p.z());
  const QuadraticTets q = quadratic_elements ? quadratic(f) : QuadraticTets{};
  const Elements el = elements_of(f, quadratic_elements ? &q : nullptr);
  diefill::write_file_atomic(dir / "fill.inp", mesh_deck(f, el, quadratic_elements ? &q : nullptr, heading, table_z));
  diefill::write_file_atomic(dir / "fill_abaqus.inp", abaqus_state(f, el));
  diefill::write_file_atomic(dir / "fill_calculix.inp", calculix_state(f, el));
  diefill::write_file_atomic(dir / "fill.vtu", vtu(f, el));
  return el.nodes->size();
}

}  // namespace post
