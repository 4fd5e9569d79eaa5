#include "postprocess/fem.hpp"

#include <algorithm>
#include <cmath>

namespace post {

namespace {

using Tet = std::array<Vec3, 4>;

double volume(const Tet& t) { return std::abs(geometry::tet_volume(t[0], t[1], t[2], t[3])); }

// A triangular prism (a0 a1 a2 below, b0 b1 b2 above, ai joined to bi) as three tetrahedra.
void add_prism(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0, const Vec3& b1, const Vec3& b2,
               std::vector<Tet>& out) {
  out.push_back({a0, a1, a2, b0});
  out.push_back({a1, a2, b0, b1});
  out.push_back({a2, b0, b1, b2});
}

// The part of `t` where x[axis] * side <= bound * side, as tetrahedra appended to `out`.
void clip(const Tet& t, int axis, double bound, double side, std::vector<Tet>& out) {
  std::array<double, 4> s;
  int in[4], out_[4], n_in = 0, n_out = 0;
  for (int k = 0; k < 4; ++k) {
    s[k] = side * (t[k][axis] - bound);
    if (s[k] <= 0) in[n_in++] = k;
    else out_[n_out++] = k;
  }
  auto cut = [&](int a, int b) { return Vec3(t[a] + (t[b] - t[a]) * (s[a] / (s[a] - s[b]))); };
  switch (n_in) {
    case 4: out.push_back(t); break;
    case 1: out.push_back({t[in[0]], cut(in[0], out_[0]), cut(in[0], out_[1]), cut(in[0], out_[2])}); break;
    case 2: {
      const int a = in[0], b = in[1], c = out_[0], d = out_[1];
      add_prism(t[a], cut(a, c), cut(a, d), t[b], cut(b, c), cut(b, d), out);
      break;
    }
    case 3: {
      const int d = out_[0];
      add_prism(t[in[0]], t[in[1]], t[in[2]], cut(in[0], d), cut(in[1], d), cut(in[2], d), out);
      break;
    }
    default: break;
  }
}

std::array<Vec3, 4> corners(const geometry::TetMesh& m, std::size_t e) {
  const geometry::Tet& t = m.tets[e];
  return {m.nodes[t[0]], m.nodes[t[1]], m.nodes[t[2]], m.nodes[t[3]]};
}

struct Overlap {
  std::size_t voxel;
  double volume;
};

// Every voxel of `grid` the tetrahedron reaches, with the volume they share.
std::vector<Overlap> overlaps(const Tet& t, const VoxelGrid& g) {
  Vec3 lo = t[0], hi = t[0];
  for (const Vec3& p : t) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const std::array<int, 3> n = {g.nx, g.ny, g.nz};
  std::array<int, 3> first, last;
  for (int d = 0; d < 3; ++d) {
    first[d] = std::clamp(int(std::floor((lo[d] - g.origin[d]) / g.voxel)), 0, n[d] - 1);
    last[d] = std::clamp(int(std::floor((hi[d] - g.origin[d]) / g.voxel)), 0, n[d] - 1);
  }
  std::vector<Overlap> out;
  for (int i = first[0]; i <= last[0]; ++i)
    for (int j = first[1]; j <= last[1]; ++j)
      for (int k = first[2]; k <= last[2]; ++k) {
        const Vec3 vlo = g.origin + g.voxel * Vec3(i, j, k);
        const double v = tet_box_overlap(t, vlo, vlo + Vec3::Constant(g.voxel));
        if (v > 0) out.push_back({g.index(i, j, k), v});
      }
  return out;
}

// FemFill from a binned field: each element's share of its voxels' solid [m³] over its share of
// their cavity, the wall correction of the density field (postprocess/density.hpp) with the
// element for the region. A share of solid over the element's own volume would put the powder
// between the die's wall and the mesh's chords into the elements at the wall; the ratio keeps
// each element at the density of the cavity it covers, and the mass of that sliver is what the
// hand-off misses (measured, fem.mass_error_rel). Nothing is averaged beyond a sub-voxel, so the
// looser layer along the walls stays in the elements there.
FemFill share_voxels(geometry::TetMesh m, const VoxelGrid& grid, const std::vector<double>& solid,
                     const std::vector<double>& cavity_fraction, double material_density) {
  FemFill f;
  f.sub_voxel_m = grid.voxel;
  f.material_density = material_density;
  f.mesh = std::move(m);
  const std::size_t elements = f.mesh.tets.size();
  std::vector<std::vector<Overlap>> shares(elements);
#pragma omp parallel for schedule(dynamic, 64)
  for (std::size_t e = 0; e < elements; ++e) shares[e] = overlaps(corners(f.mesh, e), grid);
  std::vector<double> covered(grid.size(), 0.0);
  for (const auto& list : shares)
    for (const Overlap& o : list) covered[o.voxel] += o.volume;

  f.element_volume.resize(elements);
  f.element_fraction.resize(elements);
  const double voxel_volume = grid.voxel_volume();
  for (std::size_t e = 0; e < elements; ++e) {
    f.element_volume[e] = volume(corners(f.mesh, e));
    double solid_share = 0, cavity_share = 0;
    for (const Overlap& o : shares[e]) {
      const double part = o.volume / covered[o.voxel];
      solid_share += solid[o.voxel] * part;
      cavity_share += cavity_fraction[o.voxel] * voxel_volume * part;
    }
    f.element_fraction[e] = cavity_share > 0 ? solid_share / cavity_share : 0.0;
    f.solid_volume_m3 += f.element_fraction[e] * f.element_volume[e];
  }
  for (std::size_t n = 0; n < grid.size(); ++n) {
    f.binned_solid_m3 += solid[n];
    if (covered[n] <= 0) f.outside_mesh_m3 += solid[n];
  }
  f.node_fraction = average_to_nodes(f.mesh, f.element_fraction, f.element_volume);
  return f;
}

}  // namespace

double tet_box_overlap(const std::array<Vec3, 4>& tet, const Vec3& lo, const Vec3& hi) {
  std::vector<Tet> pieces = {tet}, next;
  for (int axis = 0; axis < 3; ++axis)
    for (const auto& [bound, side] : {std::pair{hi[axis], 1.0}, std::pair{lo[axis], -1.0}}) {
      next.clear();
      for (const Tet& t : pieces) clip(t, axis, bound, side, next);
      pieces.swap(next);
      if (pieces.empty()) return 0.0;
    }
  double v = 0;
  for (const Tet& t : pieces) v += volume(t);
  return v;
}

FemFill fill_elements(geometry::TetMesh m, const std::vector<Grain>& grains, const CavityShape& cavity, double sub_voxel,
                      double material_density) {
  // Every grain whole, up to the table, whose plane is a voxel face (grain volume above it is
  // not in the cavity).
  double reach = 0;
  for (const Grain& g : grains) reach = std::max(reach, g.radius);
  const Vec3 lo = cavity.lo - Vec3::Constant(reach);
  const Vec3 hi(cavity.hi.x() + reach, cavity.hi.y() + reach, cavity.hi.z());
  const VoxelGrid grid = grid_covering(lo, hi, sub_voxel, Vec3(0.5 * (lo.x() + hi.x()), 0.5 * (lo.y() + hi.y()), hi.z()));
  std::vector<double> solid;
  bin_exact(grains, grid, solid);
  const std::vector<double> cavity_fraction = cavity_fractions(grid, cavity.distance, cavity.lo, cavity.hi, 3).fraction;
  return share_voxels(std::move(m), grid, solid, cavity_fraction, material_density);
}

std::vector<double> average_to_nodes(const geometry::TetMesh& m, const std::vector<double>& value,
                                     const std::vector<double>& volume) {
  std::vector<double> weight(m.nodes.size(), 0.0), sum(m.nodes.size(), 0.0);
  for (std::size_t e = 0; e < m.tets.size(); ++e)
    for (int node : m.tets[e]) {
      weight[std::size_t(node)] += volume[e];
      sum[std::size_t(node)] += volume[e] * value[e];
    }
  for (std::size_t n = 0; n < sum.size(); ++n) sum[n] = weight[n] > 0 ? sum[n] / weight[n] : 0.0;
  return sum;
}

QuadraticTets quadratic(const FemFill& f) {
  QuadraticTets q;
  q.nodes = f.mesh.nodes;
  q.node_fraction = f.node_fraction;
  auto middle_of = [&](int a, int b) {
    auto [it, added] = q.middle_of_edge.emplace(std::minmax(a, b), int(q.nodes.size()));
    if (added) {
      q.nodes.push_back(0.5 * (f.mesh.nodes[a] + f.mesh.nodes[b]));
      q.node_fraction.push_back(0.5 * (f.node_fraction[a] + f.node_fraction[b]));
    }
    return it->second;
  };
  constexpr int edges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
  for (const geometry::Tet& t : f.mesh.tets) {
    std::array<int, 10> e;
    for (int k = 0; k < 4; ++k) e[k] = t[k];
    for (int k = 0; k < 6; ++k) e[4 + k] = middle_of(t[edges[k][0]], t[edges[k][1]]);
    q.tets.push_back(e);
  }
  return q;
}

}  // namespace post
