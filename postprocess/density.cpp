#include "postprocess/density.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "postprocess/sphere_box.hpp"

namespace post {

VoxelGrid grid_covering(const Vec3& lo, const Vec3& hi, double h, double anchor_z) {
  VoxelGrid g;
  g.voxel = h;
  g.origin = Vec3(std::floor(lo.x() / h) * h, std::floor(lo.y() / h) * h,
                  anchor_z + std::floor((lo.z() - anchor_z) / h) * h);
  g.nx = std::max(1, int(std::ceil((hi.x() - g.origin.x()) / h - 1e-9)));
  g.ny = std::max(1, int(std::ceil((hi.y() - g.origin.y()) / h - 1e-9)));
  g.nz = std::max(1, int(std::ceil((hi.z() - g.origin.z()) / h - 1e-9)));
  return g;
}

void bin_exact(const std::vector<Grain>& grains, const VoxelGrid& g, std::vector<double>& solid) {
  solid.resize(g.size(), 0.0);
  const double h = g.voxel;
  for (const Grain& grain : grains) {
    const double r = grain.radius;
    const Vec3 lo = (grain.centre - Vec3::Constant(r) - g.origin) / h;
    const Vec3 hi = (grain.centre + Vec3::Constant(r) - g.origin) / h;
    const int i0 = std::max(0, int(std::floor(lo.x()))), i1 = std::min(g.nx - 1, int(std::floor(hi.x())));
    const int j0 = std::max(0, int(std::floor(lo.y()))), j1 = std::min(g.ny - 1, int(std::floor(hi.y())));
    const int k0 = std::max(0, int(std::floor(lo.z()))), k1 = std::min(g.nz - 1, int(std::floor(hi.z())));
    for (int i = i0; i <= i1; ++i)
      for (int j = j0; j <= j1; ++j)
        for (int k = k0; k <= k1; ++k) {
          const Vec3 a = g.origin + h * Vec3(i, j, k) - grain.centre;
          const double box_lo[3] = {a.x(), a.y(), a.z()};
          const double box_hi[3] = {a.x() + h, a.y() + h, a.z() + h};
          solid[g.index(i, j, k)] += grain.weight * sphere_box_volume(r, box_lo, box_hi);
        }
  }
}

namespace {
// Normalised Gaussian weights of one grain on the grid nodes within 3 widths.
template <typename Visit>
void gaussian_footprint(const VoxelGrid& g, const Vec3& centre, double width, Visit visit) {
  const double reach = 3 * width;
  const Vec3 lo = (centre - Vec3::Constant(reach) - g.origin) / g.voxel - Vec3::Constant(0.5);
  const Vec3 hi = (centre + Vec3::Constant(reach) - g.origin) / g.voxel - Vec3::Constant(0.5);
  const int i0 = std::max(0, int(std::ceil(lo.x()))), i1 = std::min(g.nx - 1, int(std::floor(hi.x())));
  const int j0 = std::max(0, int(std::ceil(lo.y()))), j1 = std::min(g.ny - 1, int(std::floor(hi.y())));
  const int k0 = std::max(0, int(std::ceil(lo.z()))), k1 = std::min(g.nz - 1, int(std::floor(hi.z())));
  double total = 0;
  for (int pass = 0; pass < 2; ++pass)
    for (int i = i0; i <= i1; ++i)
      for (int j = j0; j <= j1; ++j)
        for (int k = k0; k <= k1; ++k) {
          const double d2 = (g.centre(i, j, k) - centre).squaredNorm();
          if (d2 > reach * reach) continue;
          const double w = std::exp(-0.5 * d2 / (width * width));
          if (pass == 0) total += w;
          else visit(g.index(i, j, k), w / total);
        }
}
}  // namespace

void bin_gaussian(const std::vector<Grain>& grains, const VoxelGrid& g, double width, std::vector<double>& solid) {
  solid.resize(g.size(), 0.0);
  for (const Grain& grain : grains) {
    const double volume = grain.weight * 4.0 / 3.0 * std::numbers::pi * std::pow(grain.radius, 3);
    gaussian_footprint(g, grain.centre, width, [&](std::size_t n, double w) { solid[n] += volume * w; });
  }
}

std::vector<double> smooth_gaussian(const VoxelGrid& g, const std::vector<double>& field, double width) {
  std::vector<double> out(g.size(), 0.0);
  for (int i = 0; i < g.nx; ++i)
    for (int j = 0; j < g.ny; ++j)
      for (int k = 0; k < g.nz; ++k) {
        const double value = field[g.index(i, j, k)];
        if (value == 0) continue;
        gaussian_footprint(g, g.centre(i, j, k), width, [&](std::size_t n, double w) { out[n] += value * w; });
      }
  return out;
}

namespace {
double cube_fraction(const std::function<double(const Vec3&)>& distance, const Vec3& centre, double a, int depth) {
  const double d = distance(centre);
  const double half_diagonal = 0.5 * std::sqrt(3.0) * a;
  if (d >= half_diagonal) return 1.0;
  if (d <= -half_diagonal) return 0.0;
  if (depth == 0) return std::clamp(0.5 + d / a, 0.0, 1.0);
  double sum = 0.0;
  for (int c = 0; c < 8; ++c)
    sum += cube_fraction(distance, centre + 0.25 * a * Vec3((c & 1) ? 1 : -1, (c & 2) ? 1 : -1, (c & 4) ? 1 : -1),
                         0.5 * a, depth - 1);
  return sum / 8.0;
}
}  // namespace

std::vector<double> cavity_fractions(const VoxelGrid& g, const std::function<double(const Vec3&)>& distance, int depth) {
  std::vector<double> out(g.size(), 0.0);
#pragma omp parallel for schedule(dynamic, 1)
  for (int i = 0; i < g.nx; ++i)
    for (int j = 0; j < g.ny; ++j)
      for (int k = 0; k < g.nz; ++k) out[g.index(i, j, k)] = cube_fraction(distance, g.centre(i, j, k), g.voxel, depth);
  return out;
}

CorrectedField correct_for_walls(const VoxelGrid& g, const std::vector<double>& solid,
                                 const std::vector<double>& cavity, double min_cavity) {
  CorrectedField out;
  out.solid_fraction.assign(g.size(), std::numeric_limits<double>::quiet_NaN());
  out.merged.assign(g.size(), 0);
  const double v = g.voxel_volume();
  for (int i = 0; i < g.nx; ++i)
    for (int j = 0; j < g.ny; ++j)
      for (int k = 0; k < g.nz; ++k) {
        const std::size_t n = g.index(i, j, k);
        if (cavity[n] <= 0) continue;
        if (cavity[n] >= min_cavity) {
          out.solid_fraction[n] = solid[n] / (cavity[n] * v);
          continue;
        }
        // Pool with the neighbour that has the most cavity.
        std::size_t best = n;
        const int steps[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
        for (const auto& d : steps) {
          const int a = i + d[0], b = j + d[1], c = k + d[2];
          if (a < 0 || b < 0 || c < 0 || a >= g.nx || b >= g.ny || c >= g.nz) continue;
          const std::size_t m = g.index(a, b, c);
          if (cavity[m] > cavity[best]) best = m;
        }
        out.solid_fraction[n] = (solid[n] + solid[best]) / ((cavity[n] + cavity[best]) * v);
        out.merged[n] = 1;
        ++out.merged_count;
      }
  return out;
}

}  // namespace post
