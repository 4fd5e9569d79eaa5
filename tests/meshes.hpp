#pragma once
// Small test solids written in the formats users bring.
#include <fmt/core.h>

#include <string>

#include "geometry/trimesh.hpp"
#include "mesh/shapes.hpp"

namespace test {

// Unit box [0, 10]^3 mm as ASCII STL text, optionally with some faces left out or reversed.
inline std::string ascii_stl(const geometry::TriMesh& m, double scale = 1e3, const std::string& name = "part") {
  std::string s = "solid " + name + "\n";
  for (const auto& t : m.triangles) {
    s += "  facet normal 0 0 0\n    outer loop\n";
    for (int k = 0; k < 3; ++k) {
      const auto& v = m.vertices[std::size_t(t[std::size_t(k)])];
      s += fmt::format("      vertex {:.9g} {:.9g} {:.9g}\n", v.x() * scale, v.y() * scale, v.z() * scale);
    }
    s += "    endloop\n  endfacet\n";
  }
  return s + "endsolid " + name + "\n";
}

inline geometry::TriMesh box_mm(double lo, double hi) {
  return mesh::box_solid(geometry::Vec3::Constant(lo * 1e-3), geometry::Vec3::Constant(hi * 1e-3));
}

inline geometry::TriMesh reversed(geometry::TriMesh m) {
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  return m;
}

inline geometry::TriMesh joined(const geometry::TriMesh& a, const geometry::TriMesh& b) {
  geometry::TriMesh m = a;
  const int base = int(m.vertices.size());
  m.vertices.insert(m.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (auto t : b.triangles) m.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  return m;
}

}  // namespace test
