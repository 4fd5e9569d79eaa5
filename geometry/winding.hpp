#pragma once
// The generalized winding number of a triangle soup (Jacobson, Kavan & Sorkine-Hornung 2013):
// the signed solid angle the surface subtends at a point, over 4π. It is exactly 1 inside and 0
// outside a closed, outward surface, and it degrades gracefully where a file is not one: a
// crack or a small hole leaves it near 0 or 1 away from the gap, overlapping or self-intersecting
// shells add up to 1 or more inside, and a point near a large open face reads about ½. So it
// tells inside from outside where a CAD export is messy, and says where it cannot.
// Fast evaluation (Barill et al. 2018): a tree of triangles whose far clusters count as one
// dipole (their area vector at their area centroid); near triangles are summed exactly.
#include <vector>

#include "geometry/trimesh.hpp"

namespace geometry {

// Signed solid angle of triangle (a, b, c) seen from p [sr], positive when p lies behind the
// triangle's counter-clockwise face (Van Oosterom & Strackee 1983).
double solid_angle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

// Winding number of `soup` at p by the exact sum over every triangle: the reference.
double exact_winding_number(const TriMesh& soup, const Vec3& p);

class WindingNumber {
 public:
  // `accuracy` is Barill et al.'s β: a cluster counts as a dipole when p lies farther than β
  // times its radius from its centre; the truncation error then falls as β⁻².
  explicit WindingNumber(const TriMesh& soup, double accuracy = 2.0);
  double operator()(const Vec3& p) const;
  // Terms (exact solid angles and far-field dipoles) summed for p: the cost of operator()(p),
  // counted instead of timed so that what it decides is the same on every machine.
  std::size_t terms(const Vec3& p) const;

 private:
  struct Node {
    Vec3 centre;       // area-weighted centroid of the cluster's triangles
    Vec3 area_vector;  // Σ ½ (b − a) × (c − a)
    double radius;     // farthest vertex of the cluster from `centre`
    int first, count;  // the cluster's range in order_
    int left, right;   // children, -1 for a leaf
  };
  int build(int first, int count);
  template <bool counting>
  double sum(const Vec3& p, std::size_t& terms) const;
  const TriMesh& soup_;
  std::vector<int> order_;
  std::vector<Vec3> centroids_, area_vectors_;
  std::vector<Node> nodes_;
  double accuracy_;
};

}  // namespace geometry
