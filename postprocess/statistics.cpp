#include <algorithm>
#include <cmath>
#include <numeric>

#include "postprocess/field.hpp"

namespace post {

namespace {

// Cavity-weighted mean and standard deviation of the voxels' solid fractions.
struct WeightedSpread {
  double weight = 0, sum = 0, sum_squares = 0;
  void add(double value, double w) { weight += w, sum += w * value, sum_squares += w * value * value; }
  double mean() const { return weight > 0 ? sum / weight : 0; }
  double std() const { return weight > 0 ? std::sqrt(std::max(0.0, sum_squares / weight - mean() * mean())) : 0; }
};

// A profile in bins one voxel wide along `coordinate` (from lo): the cavity-weighted mean of the
// bin's wall-corrected voxels (for the exact field, the bin's solid over its cavity volume but
// where voxels were merged; for the smoothed field, whose kernel spreads solid past the wall,
// the kernel method's own ratio), kept where the bin's cavity reaches min_cavity of its voxels'
// volume (the threshold below which the wall correction pools a voxel: fewer would read a
// sliver as a value), counting the voxels that hold any cavity.
template <typename Coordinate>
Profile profile(const DensityField& f, const std::string& axis, Coordinate coordinate, double lo, double hi) {
  const VoxelGrid& g = f.grid;
  const double v = g.voxel_volume();
  const int bins = std::max(1, int(std::ceil((hi - lo) / g.voxel - 1e-9)));
  std::vector<double> cavity(std::size_t(bins), 0.0), volume(std::size_t(bins), 0.0);
  std::vector<WeightedSpread> spread(std::size_t(bins), WeightedSpread{});
  for (int i = 0; i < g.nx; ++i)
    for (int j = 0; j < g.ny; ++j)
      for (int k = 0; k < g.nz; ++k) {
        const std::size_t n = g.index(i, j, k);
        const auto b = std::size_t(std::clamp(int(std::floor((coordinate(g.centre(i, j, k)) - lo) / g.voxel)), 0, bins - 1));
        if (f.cavity[n] <= 0) continue;  // the grid's margins are no part of any bin
        volume[b] += v;
        cavity[b] += f.cavity[n] * v;
        if (std::isfinite(f.corrected.solid_fraction[n])) spread[b].add(f.corrected.solid_fraction[n], f.cavity[n]);
      }
  Profile p;
  p.axis = axis;
  for (std::size_t b = 0; b < std::size_t(bins); ++b) {
    if (cavity[b] <= 0 || cavity[b] < f.min_cavity * volume[b]) continue;
    p.position.push_back(lo + (double(b) + 0.5) * g.voxel);
    p.solid_fraction.push_back(spread[b].mean());
    p.spread.push_back(spread[b].std());
    p.cavity_volume.push_back(cavity[b]);
  }
  return p;
}

}  // namespace

FieldStatistics statistics(const DensityField& f) {
  FieldStatistics st;
  const VoxelGrid& g = f.grid;
  const double v = g.voxel_volume();
  struct Sample {
    double value, weight;
  };
  std::vector<Sample> samples;
  WeightedSpread spread;
  for (std::size_t n = 0; n < g.size(); ++n) {
    if (f.cavity[n] <= 0) continue;
    st.cavity_volume_m3 += f.cavity[n] * v;
    st.solid_volume_m3 += f.solid[n];
    const double phi = f.corrected.solid_fraction[n];
    if (!std::isfinite(phi)) continue;
    samples.push_back({phi, f.cavity[n] * v});
    spread.add(phi, f.cavity[n] * v);
  }
  st.voxels = samples.size();
  st.merged_voxels = f.corrected.merged_count;
  st.fill_ratio = st.cavity_volume_m3 > 0 ? st.solid_volume_m3 / st.cavity_volume_m3 : 0;
  st.mass_kg = st.solid_volume_m3 * f.material_density;
  if (samples.empty()) return st;
  st.mean = spread.mean();
  st.std = spread.std();
  st.cv = st.mean > 0 ? st.std / st.mean : 0;
  std::sort(samples.begin(), samples.end(), [](const Sample& a, const Sample& b) { return a.value < b.value; });
  st.min = samples.front().value;
  st.max = samples.back().value;
  for (int p : {5, 25, 50, 75, 95}) {
    double acc = 0;
    for (const Sample& s : samples) {
      acc += s.weight;
      if (acc >= spread.weight * p / 100.0) {
        st.percentiles[p] = s.value;
        break;
      }
    }
  }
  const Vec3 lo = g.origin, hi = g.origin + g.voxel * Vec3(g.nx, g.ny, g.nz);
  st.profiles.push_back(profile(f, "z", [](const Vec3& p) { return p.z(); }, lo.z(), hi.z()));
  double r_max = 0;
  for (const Vec3& corner : {lo, hi, Vec3(lo.x(), hi.y(), 0), Vec3(hi.x(), lo.y(), 0)})
    r_max = std::max(r_max, (corner.head<2>() - f.centre.head<2>()).norm());
  st.profiles.push_back(profile(f, "r", [&](const Vec3& p) { return (p.head<2>() - f.centre.head<2>()).norm(); }, 0.0, r_max));
  st.profiles.push_back(profile(f, "x", [](const Vec3& p) { return p.x(); }, lo.x(), hi.x()));
  return st;
}

std::vector<RegionStatistics> region_statistics(const VoxelGrid& g, const std::vector<double>& solid,
                                                const std::vector<double>& cavity, const std::vector<Region>& regions) {
  std::vector<RegionStatistics> out;
  for (const Region& region : regions) {
    RegionStatistics r;
    r.name = region.name;
    for (std::size_t n = 0; n < g.size(); ++n) {
      if (cavity[n] <= 0) continue;  // the kernel's grid reaches past the cavity, above the table
      r.cavity_volume_m3 += region.share[n] * cavity[n] * g.voxel_volume();
      r.solid_volume_m3 += region.share[n] * solid[n];
    }
    r.fill_ratio = r.cavity_volume_m3 > 0 ? r.solid_volume_m3 / r.cavity_volume_m3 : 0;
    out.push_back(r);
  }
  return out;
}

}  // namespace post
