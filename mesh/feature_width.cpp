#include "mesh/feature_width.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "mesh/exact.hpp"

namespace mesh {

double FeatureWidths::share_below(double width) const {
  double volume = 0;
  for (const Crossing& c : crossings)
    if (c.width <= width) volume += c.volume;
  return cavity_volume > 0 ? std::min(1.0, volume / cavity_volume) : 0.0;
}

const FeatureWidths::Crossing* FeatureWidths::narrowest() const {
  const auto it = std::min_element(crossings.begin(), crossings.end(), [](const Crossing& a, const Crossing& b) { return a.width < b.width; });
  return it == crossings.end() ? nullptr : &*it;
}

FeatureWidths feature_widths(const geometry::TriMesh& cavity, double table_z, double spacing) {
  const ExactSurface surface(cavity);
  const geometry::Box box = geometry::bounding_box(cavity);
  const geometry::Vec3 size = box.size();
  const int nx = std::max(2, int(std::ceil(size.x() / spacing))), ny = std::max(2, int(std::ceil(size.y() / spacing))),
            nz = std::max(2, int(std::ceil(size.z() / spacing)));
  // Per grid point inside the cavity: its closest wall point, unless that lies on the opening.
  std::vector<std::optional<geometry::Vec3>> wall(std::size_t(nx) * std::size_t(ny) * std::size_t(nz));
  const auto at = [&](int i, int j, int k) { return (std::size_t(i) * std::size_t(ny) + std::size_t(j)) * std::size_t(nz) + std::size_t(k); };
  const auto point = [&](int i, int j, int k) { return geometry::Vec3(box.lo + spacing * geometry::Vec3(i + 0.5, j + 0.5, k + 0.5)); };
  const double opening = 1e-9 * std::max(1.0, size.norm());
  std::size_t inside = 0;  // the cavity below the table as sampled (a part cut at its widest section reaches above it)
#pragma omp parallel for collapse(2) schedule(dynamic, 4) reduction(+ : inside)
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) {
        const geometry::Vec3 p = point(i, j, k);
        if (p.z() >= table_z || !surface.inside(p)) continue;
        ++inside;
        const geometry::Vec3 c = surface.closest_point(p);
        if (c.z() < table_z - opening) wall[at(i, j, k)] = c;
      }
  FeatureWidths out;
  out.cavity_volume = double(inside) * spacing * spacing * spacing;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) {
        const auto& c = wall[at(i, j, k)];
        if (!c) continue;
        const geometry::Vec3 p = point(i, j, k);
        for (int axis = 0; axis < 3; ++axis) {
          const int ii = i + (axis == 0), jj = j + (axis == 1), kk = k + (axis == 2);
          if (ii >= nx || jj >= ny || kk >= nz) continue;
          const auto& d = wall[at(ii, jj, kk)];
          if (!d) continue;
          const geometry::Vec3 q = point(ii, jj, kk);
          if ((p - *c).normalized().dot((q - *d).normalized()) >= -0.5) continue;
          // The grid's edges cross a plane whose unit normal is n as often as h²/|n|₁ per area.
          const geometry::Vec3 across = *d - *c;
          const double width = across.norm();
          out.crossings.push_back({width, width * spacing * spacing / (across / width).lpNorm<1>(), *c, *d});
        }
      }
  return out;
}

}  // namespace mesh
