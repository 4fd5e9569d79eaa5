#include "geometry/winding.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace geometry {

namespace {
constexpr int leaf_size = 8;
constexpr double four_pi = 4.0 * std::numbers::pi;
}  // namespace

// Van Oosterom & Strackee's formula, in scalars: the survey and the band's signing call it
// billions of times, and Eigen's small temporaries made it 3.8 times slower than this under
// the sanitizers' -O1 (the same operations in the same order: the same bits at -O3).
double solid_angle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const double ux = a.x() - p.x(), uy = a.y() - p.y(), uz = a.z() - p.z();
  const double vx = b.x() - p.x(), vy = b.y() - p.y(), vz = b.z() - p.z();
  const double wx = c.x() - p.x(), wy = c.y() - p.y(), wz = c.z() - p.z();
  const double lu = std::sqrt(ux * ux + uy * uy + uz * uz), lv = std::sqrt(vx * vx + vy * vy + vz * vz),
               lw = std::sqrt(wx * wx + wy * wy + wz * wz);
  const double numerator = ux * (vy * wz - vz * wy) + uy * (vz * wx - vx * wz) + uz * (vx * wy - vy * wx);
  const double uv = ux * vx + uy * vy + uz * vz, uw = ux * wx + uy * wy + uz * wz, vw = vx * wx + vy * wy + vz * wz;
  const double denominator = lu * lv * lw + uv * lw + uw * lv + vw * lu;
  return 2.0 * std::atan2(numerator, denominator);
}

double exact_winding_number(const TriMesh& soup, const Vec3& p) {
  double sum = 0.0;
  for (const Triangle& t : soup.triangles)
    sum += solid_angle(p, soup.vertices[t[0]], soup.vertices[t[1]], soup.vertices[t[2]]);
  return sum / four_pi;
}

WindingNumber::WindingNumber(const TriMesh& soup, double accuracy) : soup_(soup), accuracy_(accuracy) {
  const std::size_t n = soup.triangles.size();
  order_.resize(n);
  centroids_.resize(n);
  area_vectors_.resize(n);
  for (std::size_t f = 0; f < n; ++f) {
    const Triangle& t = soup.triangles[f];
    const Vec3 &a = soup.vertices[t[0]], &b = soup.vertices[t[1]], &c = soup.vertices[t[2]];
    order_[f] = int(f);
    centroids_[f] = (a + b + c) / 3.0;
    area_vectors_[f] = 0.5 * (b - a).cross(c - a);
  }
  nodes_.reserve(2 * n / leaf_size + 2);
  if (n > 0) build(0, int(n));
}

int WindingNumber::build(int first, int count) {
  const int index = int(nodes_.size());
  nodes_.push_back(Node{Vec3::Zero(), Vec3::Zero(), 0.0, first, count, -1, -1});
  Vec3 weighted = Vec3::Zero(), area_vector = Vec3::Zero(), mean = Vec3::Zero();
  double area = 0.0;
  Box box;
  for (int i = first; i < first + count; ++i) {
    const int f = order_[std::size_t(i)];
    const double a = area_vectors_[std::size_t(f)].norm();
    weighted += a * centroids_[std::size_t(f)];
    mean += centroids_[std::size_t(f)];
    area += a;
    area_vector += area_vectors_[std::size_t(f)];
    box.extend(centroids_[std::size_t(f)]);
  }
  Node node{area > 0 ? Vec3(weighted / area) : Vec3(mean / count), area_vector, 0.0, first, count, -1, -1};
  for (int i = first; i < first + count; ++i)
    for (int k : soup_.triangles[std::size_t(order_[std::size_t(i)])])
      node.radius = std::max(node.radius, (soup_.vertices[std::size_t(k)] - node.centre).norm());
  if (count > leaf_size) {
    int axis = 0;
    box.size().maxCoeff(&axis);
    const int half = count / 2;
    std::nth_element(order_.begin() + first, order_.begin() + first + half, order_.begin() + first + count,
                     [&](int x, int y) { return centroids_[std::size_t(x)][axis] < centroids_[std::size_t(y)][axis]; });
    node.left = build(first, half);
    node.right = build(first + half, count - half);
  }
  nodes_[std::size_t(index)] = node;
  return index;
}

template <bool counting>
double WindingNumber::sum(const Vec3& p, std::size_t& terms) const {
  if (nodes_.empty()) return 0.0;
  double total = 0.0;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[std::size_t(stack[--top])];
    const Vec3 r = node.centre - p;
    const double distance = r.norm();
    if (distance > accuracy_ * node.radius) {
      if constexpr (counting) ++terms;
      total += node.area_vector.dot(r) / (distance * distance * distance);
    } else if (node.left < 0) {
      if constexpr (counting) terms += std::size_t(node.count);
      for (int i = node.first; i < node.first + node.count; ++i) {
        const Triangle& t = soup_.triangles[std::size_t(order_[std::size_t(i)])];
        total += solid_angle(p, soup_.vertices[t[0]], soup_.vertices[t[1]], soup_.vertices[t[2]]);
      }
    } else {
      stack[top++] = node.left;
      stack[top++] = node.right;
    }
  }
  return total;
}

double WindingNumber::operator()(const Vec3& p) const {
  std::size_t unused = 0;
  return sum<false>(p, unused) / four_pi;
}

std::size_t WindingNumber::terms(const Vec3& p) const {
  std::size_t terms = 0;
  sum<true>(p, terms);
  return terms;
}

}  // namespace geometry
