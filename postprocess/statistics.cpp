#include <algorithm>
#include <cmath>
#include <numeric>

#include "postprocess/field.hpp"

namespace post {

FieldStatistics statistics(const DensityField& f, const Vec3& axis_xy, int bins) {
  FieldStatistics st;
  const VoxelGrid& g = f.grid;
  const double v = g.voxel_volume();
  struct Sample {
    double value, weight;
  };
  std::vector<Sample> samples;
  for (std::size_t n = 0; n < g.size(); ++n) {
    if (f.cavity[n] <= 0) continue;
    st.cavity_volume_m3 += f.cavity[n] * v;
    st.solid_volume_m3 += f.solid[n];
    const double phi = f.corrected.solid_fraction[n];
    if (std::isfinite(phi)) samples.push_back({phi, f.cavity[n] * v});
  }
  st.voxels = samples.size();
  st.merged_voxels = f.corrected.merged_count;
  st.fill_ratio = st.cavity_volume_m3 > 0 ? st.solid_volume_m3 / st.cavity_volume_m3 : 0;
  st.mass_kg = st.solid_volume_m3 * f.material_density;
  if (samples.empty()) return st;
  double weight = 0, sum = 0;
  for (const Sample& s : samples) weight += s.weight, sum += s.weight * s.value;
  st.mean = sum / weight;
  double var = 0;
  for (const Sample& s : samples) var += s.weight * (s.value - st.mean) * (s.value - st.mean);
  st.std = std::sqrt(var / weight);
  st.cv = st.mean > 0 ? st.std / st.mean : 0;
  std::sort(samples.begin(), samples.end(), [](const Sample& a, const Sample& b) { return a.value < b.value; });
  st.min = samples.front().value;
  st.max = samples.back().value;
  for (int p : {5, 25, 50, 75, 95}) {
    double acc = 0;
    for (const Sample& s : samples) {
      acc += s.weight;
      if (acc >= weight * p / 100.0) {
        st.percentiles[p] = s.value;
        break;
      }
    }
  }
  // Profiles: cavity-weighted means in bins along z, the radius about the axis, and x.
  auto profile = [&](const std::string& axis, auto coordinate, double lo, double hi) {
    Profile pr;
    pr.axis = axis;
    std::vector<double> solid(std::size_t(bins), 0.0), cavity(std::size_t(bins), 0.0);
    for (int i = 0; i < g.nx; ++i)
      for (int j = 0; j < g.ny; ++j)
        for (int k = 0; k < g.nz; ++k) {
          const std::size_t n = g.index(i, j, k);
          if (f.cavity[n] <= 0) continue;
          const int b = std::clamp(int((coordinate(g.centre(i, j, k)) - lo) / (hi - lo) * bins), 0, bins - 1);
          solid[std::size_t(b)] += f.solid[n];
          cavity[std::size_t(b)] += f.cavity[n] * v;
        }
    for (int b = 0; b < bins; ++b) {
      if (cavity[std::size_t(b)] <= 0) continue;
      pr.position.push_back(lo + (b + 0.5) * (hi - lo) / bins);
      pr.solid_fraction.push_back(solid[std::size_t(b)] / cavity[std::size_t(b)]);
      pr.cavity_volume.push_back(cavity[std::size_t(b)]);
    }
    st.profiles.push_back(pr);
  };
  const Vec3 lo = g.origin, hi = g.origin + g.voxel * Vec3(g.nx, g.ny, g.nz);
  profile("z", [](const Vec3& p) { return p.z(); }, lo.z(), hi.z());
  double r_max = 0;
  for (const Vec3& corner : {lo, hi, Vec3(lo.x(), hi.y(), 0), Vec3(hi.x(), lo.y(), 0)})
    r_max = std::max(r_max, (corner.head<2>() - axis_xy.head<2>()).norm());
  profile("r", [&](const Vec3& p) { return (p.head<2>() - axis_xy.head<2>()).norm(); }, 0.0, r_max);
  profile("x", [](const Vec3& p) { return p.x(); }, lo.x(), hi.x());
  return st;
}

}  // namespace post
