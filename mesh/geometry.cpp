#include "mesh/geometry.hpp"

#include <cmath>
#include <map>
#include <numbers>

namespace mesh {

std::vector<Segment> sharp_edges(const geometry::TriMesh& mesh, double angle_deg) {
  std::map<std::pair<int, int>, std::vector<geometry::Vec3>> normals_of_edge;
  for (const geometry::Triangle& t : mesh.triangles) {
    const geometry::Vec3 n = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                                 .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]])
                                 .normalized();
    for (int k = 0; k < 3; ++k) normals_of_edge[std::minmax(t[k], t[(k + 1) % 3])].push_back(n);
  }
  const double cos_limit = std::cos(angle_deg * std::numbers::pi / 180.0);
  std::vector<Segment> out;
  for (const auto& [edge, normals] : normals_of_edge) {
    const bool sharp = normals.size() != 2 || normals[0].dot(normals[1]) < cos_limit;
    if (sharp) out.push_back({mesh.vertices[edge.first], mesh.vertices[edge.second]});
  }
  return out;
}

}  // namespace mesh
