#pragma once
// Small exact geometric kernels shared by the exact reference, verification and tests.
#include "geometry/trimesh.hpp"

namespace mesh {

// Closest point to p on triangle abc (Ericson, Real-Time Collision Detection, §5.1.5).
inline geometry::Vec3 closest_point_on_triangle(const geometry::Vec3& p, const geometry::Vec3& a, const geometry::Vec3& b, const geometry::Vec3& c) {
  const geometry::Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const geometry::Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const geometry::Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

inline double distance_to_segment(const geometry::Vec3& p, const geometry::Vec3& a, const geometry::Vec3& b) {
  const geometry::Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

struct Segment {
  geometry::Vec3 a, b;
};

// Edges whose two triangles meet at more than `angle_deg` between their normals, plus
// boundary edges: where a distance field has a kink.
std::vector<Segment> sharp_edges(const geometry::TriMesh& mesh, double angle_deg);

}  // namespace mesh
