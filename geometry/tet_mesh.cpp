// Tetrahedron measures for the FEM hand-off's report (no CGAL: the mesh as handed over is judged).
#include <algorithm>
#include <cmath>

#include "geometry/tet_mesh.hpp"

namespace geometry {

double tet_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return (b - a).cross(c - a).dot(d - a) / 6.0;
}

namespace {

// The six dihedral angles: the angle between the two faces meeting at each edge.
void dihedral_range(const std::array<Vec3, 4>& p, double& lo, double& hi) {
  constexpr int edges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  for (const auto& e : edges) {
    int others[2], n = 0;
    for (int k = 0; k < 4; ++k)
      if (k != e[0] && k != e[1]) others[n++] = k;
    const Vec3 axis = (p[e[1]] - p[e[0]]).normalized();
    Vec3 u = p[others[0]] - p[e[0]], v = p[others[1]] - p[e[0]];
    u -= u.dot(axis) * axis;
    v -= v.dot(axis) * axis;
    const double angle = std::atan2(u.cross(v).norm(), u.dot(v)) * 180.0 / M_PI;
    lo = std::min(lo, angle);
    hi = std::max(hi, angle);
  }
}

// 3 r_in / r_circum; r_in = 3V / (face areas), r_circum from the circumcentre's linear system.
double radius_ratio(const std::array<Vec3, 4>& p) {
  const double volume = std::abs(tet_volume(p[0], p[1], p[2], p[3]));
  double area = 0;
  constexpr int faces[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  for (const auto& f : faces) area += 0.5 * (p[f[1]] - p[f[0]]).cross(p[f[2]] - p[f[0]]).norm();
  const Vec3 a = p[1] - p[0], b = p[2] - p[0], c = p[3] - p[0];
  const Vec3 offset = (a.squaredNorm() * b.cross(c) + b.squaredNorm() * c.cross(a) + c.squaredNorm() * a.cross(b)) /
                      (2.0 * a.dot(b.cross(c)));
  const double r_in = 3.0 * volume / area, r_circum = offset.norm();
  return r_circum > 0 ? 3.0 * r_in / r_circum : 0.0;
}

}  // namespace

TetQuality tet_quality(const TetMesh& m) {
  TetQuality q;
  double ratio_sum = 0;
  for (const Tet& t : m.tets) {
    const std::array<Vec3, 4> p = {m.nodes[t[0]], m.nodes[t[1]], m.nodes[t[2]], m.nodes[t[3]]};
    if (!(tet_volume(p[0], p[1], p[2], p[3]) > 0)) {
      ++q.inverted;
      continue;
    }
    dihedral_range(p, q.min_dihedral_deg, q.max_dihedral_deg);
    const double ratio = radius_ratio(p);
    q.min_radius_ratio = std::min(q.min_radius_ratio, ratio);
    ratio_sum += ratio;
  }
  q.mean_radius_ratio = m.tets.empty() ? 0.0 : ratio_sum / double(m.tets.size());
  return q;
}

}  // namespace geometry
