#include "mesh/weld.hpp"

#include <cmath>
#include <unordered_map>

namespace mesh {

namespace {

struct Cell {
  long long x, y, z;
  bool operator==(const Cell&) const = default;
};

struct CellHash {
  std::size_t operator()(const Cell& c) const {
    return std::size_t(c.x * 73856093LL ^ c.y * 19349663LL ^ c.z * 83492791LL);
  }
};

}  // namespace

WeldedMesh weld_close_vertices(const geometry::TriMesh& mesh, double distance) {
  WeldedMesh out;
  out.mesh.vertices = mesh.vertices;
  const std::size_t n = mesh.vertices.size();
  // Cells of the weld distance: the vertices closer than it lie in the 27 cells around.
  const auto cell_of = [distance](const geometry::Vec3& p) {
    return Cell{std::llround(std::floor(p.x() / distance)), std::llround(std::floor(p.y() / distance)),
                std::llround(std::floor(p.z() / distance))};
  };
  std::unordered_map<Cell, std::vector<int>, CellHash> cells;
  cells.reserve(n);
  for (std::size_t v = 0; v < n; ++v) cells[cell_of(mesh.vertices[v])].push_back(int(v));

  std::vector<int> welded_to(n, -1);
  for (std::size_t v = 0; v < n; ++v) {
    if (welded_to[v] >= 0) continue;
    welded_to[v] = int(v);
    const geometry::Vec3& p = mesh.vertices[v];
    const Cell c = cell_of(p);
    for (long long dx = -1; dx <= 1; ++dx)
      for (long long dy = -1; dy <= 1; ++dy)
        for (long long dz = -1; dz <= 1; ++dz) {
          const auto found = cells.find(Cell{c.x + dx, c.y + dy, c.z + dz});
          if (found == cells.end()) continue;
          for (const int w : found->second) {
            if (std::size_t(w) <= v || welded_to[std::size_t(w)] >= 0) continue;
            const double moved = (mesh.vertices[std::size_t(w)] - p).norm();
            if (moved >= distance) continue;
            welded_to[std::size_t(w)] = int(v);
            ++out.merged;
            out.moved_m = std::max(out.moved_m, moved);
          }
        }
  }
  for (geometry::Triangle t : mesh.triangles) {
    for (int& corner : t) corner = welded_to[std::size_t(corner)];
    if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) out.mesh.triangles.push_back(t);
  }
  return out;
}

}  // namespace mesh
