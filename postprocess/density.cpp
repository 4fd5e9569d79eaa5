#include "postprocess/density.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/core.h>

#include "core/error.hpp"
#include "postprocess/sphere_box.hpp"

namespace post {

VoxelGrid grid_covering(const Vec3& lo, const Vec3& hi, double h, const Vec3& anchor) {
  // Scenes bound their voxels (pipeline/preflight.hpp); this catches any other caller before a
  // count overflows an int.
  if (!(h > 0) || !((hi - lo).maxCoeff() / h < 1e6))
    throw diefill::InputError("density", "voxel",
                              fmt::format("voxels of {:.3g} m over {:.3g} m would be over a million along one axis",
                                          h, (hi - lo).maxCoeff()),
                              "Give a coarser voxel");
  VoxelGrid g;
  g.voxel = h;
  const Vec3 face = anchor - Vec3(0.5 * h, 0.5 * h, 0);
  g.origin = face + h * ((lo - face) / h).array().floor().matrix();
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
// One axis of the kernel: the weights of the nodes within 3 widths of `at`, normalised over all
// of them, on the grid or beyond it (renormalising on the grid's nodes alone would weigh a
// grain near the grid's edge by where the edge happens to be; weight beyond the grid is lost,
// and fields of the kernel method reach 3 widths past the cavity, density_stage). A point takes
// the Gaussian's values at the nodes; a segment of length `extent` around `at` (a voxel's
// cavity along this axis) the Gaussian's integral over each node's interval of it.
struct AxisWeights {
  int first = 0;  // node index of weight[0]; may lie off the grid
  std::vector<double> weight;
};

AxisWeights axis_weights(double origin, double h, double at, double width, double extent) {
  AxisWeights a;
  const double reach = 3 * width;
  a.first = int(std::ceil((at - reach - origin) / h - 0.5));
  const int last = int(std::floor((at + reach - origin) / h - 0.5));
  double total = 0;
  for (int n = a.first; n <= last; ++n) {
    const double u = origin + (n + 0.5) * h - at;
    const double w = extent > 0 ? std::erf((u + 0.5 * extent) / (std::numbers::sqrt2 * width)) -
                                      std::erf((u - 0.5 * extent) / (std::numbers::sqrt2 * width))
                                : std::exp(-0.5 * u * u / (width * width));
    a.weight.push_back(w);
    total += w;
  }
  for (double& w : a.weight) w /= total;
  return a;
}

// The separable kernel around `at` (a point, or a cube of side `extent`), visited on the grid.
template <typename Visit>
void gaussian_footprint(const VoxelGrid& g, const Vec3& at, double width, double extent, Visit visit) {
  const AxisWeights x = axis_weights(g.origin.x(), g.voxel, at.x(), width, extent);
  const AxisWeights y = axis_weights(g.origin.y(), g.voxel, at.y(), width, extent);
  const AxisWeights z = axis_weights(g.origin.z(), g.voxel, at.z(), width, extent);
  for (std::size_t a = 0; a < x.weight.size(); ++a) {
    const int i = x.first + int(a);
    if (i < 0 || i >= g.nx) continue;
    for (std::size_t b = 0; b < y.weight.size(); ++b) {
      const int j = y.first + int(b);
      if (j < 0 || j >= g.ny) continue;
      for (std::size_t c = 0; c < z.weight.size(); ++c) {
        const int k = z.first + int(c);
        if (k >= 0 && k < g.nz) visit(g.index(i, j, k), x.weight[a] * y.weight[b] * z.weight[c]);
      }
    }
  }
}
}  // namespace

void bin_gaussian(const std::vector<Grain>& grains, const VoxelGrid& g, double width, std::vector<double>& solid) {
  solid.resize(g.size(), 0.0);
  for (const Grain& grain : grains) {
    const double volume = grain.weight * 4.0 / 3.0 * std::numbers::pi * std::pow(grain.radius, 3);
    gaussian_footprint(g, grain.centre, width, 0.0, [&](std::size_t n, double w) { solid[n] += volume * w; });
  }
}

std::vector<double> smooth_gaussian(const VoxelGrid& g, const CavityVolumes& cavity, double width) {
  std::vector<double> out(g.size(), 0.0);
  for (std::size_t n = 0; n < g.size(); ++n) {
    const double value = cavity.fraction[n];
    if (value == 0) continue;
    gaussian_footprint(g, cavity.centroid[n], width, g.voxel, [&](std::size_t m, double w) { out[m] += value * w; });
  }
  return out;
}

namespace {
// Fractions within rounding of 0 or 1 are 0 or 1 (a face half a cube away reads 1e-17, not 0).
double snapped(double fraction) { return fraction < 1e-12 ? 0.0 : fraction > 1 - 1e-12 ? 1.0 : fraction; }

// The part of a cube inside a region, over the cube's volume, and its first moment (the part's
// centroid times that fraction).
struct CubePart {
  double fraction = 0;
  Vec3 moment = Vec3::Zero();
};

// `distance` is into the cavity: the free side of the walls within the box.
CubePart cube_part(const std::function<double(const Vec3&)>& distance, const Vec3& centre, double a, int depth) {
  const double d = distance(centre);
  const double half_diagonal = 0.5 * std::sqrt(3.0) * a;
  if (d >= half_diagonal) return {1.0, centre};
  if (d <= -half_diagonal) return {};
  if (depth == 0) {
    const double free = snapped(std::clamp(0.5 + d / a, 0.0, 1.0));
    return {free, free * centre};
  }
  CubePart sum;
  for (int c = 0; c < 8; ++c) {
    const CubePart child =
        cube_part(distance, centre + 0.25 * a * Vec3((c & 1) ? 1 : -1, (c & 2) ? 1 : -1, (c & 4) ? 1 : -1), 0.5 * a, depth - 1);
    sum.fraction += child.fraction / 8.0, sum.moment += child.moment / 8.0;
  }
  return sum;
}
}  // namespace

CavityVolumes cavity_fractions(const VoxelGrid& g, const std::function<double(const Vec3&)>& distance, const Vec3& lo,
                               const Vec3& hi, int depth) {
  const auto into_cavity = [&](const Vec3& p) { return std::min({distance(p), (p - lo).minCoeff(), (hi - p).minCoeff()}); };
  CavityVolumes out{std::vector<double>(g.size(), 0.0), std::vector<Vec3>(g.size(), Vec3::Zero())};
#pragma omp parallel for schedule(dynamic, 1)
  for (int i = 0; i < g.nx; ++i)
    for (int j = 0; j < g.ny; ++j)
      for (int k = 0; k < g.nz; ++k) {
        const std::size_t n = g.index(i, j, k);
        const CubePart part = cube_part(into_cavity, g.centre(i, j, k), g.voxel, depth);
        out.fraction[n] = part.fraction;
        out.centroid[n] = part.fraction > 0 ? Vec3(part.moment / part.fraction) : g.centre(i, j, k);
      }
  return out;
}

namespace {
// The pool a voxel belongs to (union-find with path halving): a sliver joins its fullest
// neighbour, which may be a sliver that joined another.
std::size_t pool_of(std::vector<std::size_t>& parent, std::size_t n) {
  while (parent[n] != n) n = parent[n] = parent[parent[n]];
  return n;
}
}  // namespace

CorrectedField correct_for_walls(const VoxelGrid& g, const std::vector<double>& solid,
                                 const std::vector<double>& cavity, double min_cavity) {
  // Every voxel of a pool carries the pool's value, the host as well as its slivers: were the
  // host to keep its own, Σ solid fraction × cavity volume would count the slivers' solid twice
  // over and miss their cavity (0.38 % of the mass on the disc at 1 mm voxels, issue 44).
  std::vector<std::size_t> parent(g.size());
  for (std::size_t n = 0; n < g.size(); ++n) parent[n] = n;
  const int steps[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (int i = 0; i < g.nx; ++i)
    for (int j = 0; j < g.ny; ++j)
      for (int k = 0; k < g.nz; ++k) {
        const std::size_t n = g.index(i, j, k);
        if (cavity[n] <= 0 || cavity[n] >= min_cavity) continue;
        std::size_t best = n;
        for (const auto& d : steps) {
          const int a = i + d[0], b = j + d[1], c = k + d[2];
          if (a < 0 || b < 0 || c < 0 || a >= g.nx || b >= g.ny || c >= g.nz) continue;
          const std::size_t m = g.index(a, b, c);
          if (cavity[m] > cavity[best]) best = m;
        }
        parent[pool_of(parent, n)] = pool_of(parent, best);
      }
  std::vector<double> pool_solid(g.size(), 0.0), pool_cavity(g.size(), 0.0);
  std::vector<std::uint32_t> pool_size(g.size(), 0);
  for (std::size_t n = 0; n < g.size(); ++n) {
    if (cavity[n] <= 0) continue;
    const std::size_t root = pool_of(parent, n);
    pool_solid[root] += solid[n];
    pool_cavity[root] += cavity[n];
    ++pool_size[root];
  }
  CorrectedField out;
  out.solid_fraction.assign(g.size(), std::numeric_limits<double>::quiet_NaN());
  out.merged.assign(g.size(), 0);
  const double v = g.voxel_volume();
  for (std::size_t n = 0; n < g.size(); ++n) {
    if (cavity[n] <= 0) continue;
    const std::size_t root = pool_of(parent, n);
    out.solid_fraction[n] = pool_solid[root] / (pool_cavity[root] * v);
    if (pool_size[root] > 1) {
      out.merged[n] = 1;
      ++out.merged_count;
    }
  }
  return out;
}

}  // namespace post
