// The FEM hand-off's geometry kernels against exact volumes (unit: they also run under the
// sanitizers).
#include <gtest/gtest.h>

#include <random>

#include "postprocess/fem.hpp"

namespace {

using post::Vec3;
using Corners = std::array<Vec3, 4>;

double abs_volume(const Corners& t) { return std::abs((t[1] - t[0]).cross(t[2] - t[0]).dot(t[3] - t[0])) / 6.0; }

// The unit cube [0, 1]^3 as the six tetrahedra around its diagonal (Kuhn's split).
std::vector<Corners> cube_tets() {
  auto corner = [](int bits) { return Vec3(bits & 1, (bits >> 1) & 1, (bits >> 2) & 1); };
  std::vector<Corners> out;
  const int axes[6][3] = {{1, 2, 4}, {1, 4, 2}, {2, 1, 4}, {2, 4, 1}, {4, 1, 2}, {4, 2, 1}};
  for (const auto& order : axes) {
    int bits = 0;
    Corners t;
    t[0] = corner(bits);
    for (int k = 0; k < 3; ++k) t[std::size_t(k) + 1] = corner(bits |= order[k]);
    out.push_back(t);
  }
  return out;
}

}  // namespace

TEST(TetBoxOverlap, SixTetsOfACubeShareAnyBoxAsTheCubeDoes) {
  // The six tetrahedra tile the cube, so their overlaps with a box add up to the box's overlap
  // with the cube: the product of the three intervals' overlaps.
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> u(-0.5, 1.5);
  const std::vector<Corners> tets = cube_tets();
  double total = 0;
  for (const Corners& t : tets) total += abs_volume(t);
  ASSERT_NEAR(total, 1.0, 1e-15);
  for (int trial = 0; trial < 200; ++trial) {
    Vec3 a(u(random), u(random), u(random)), b(u(random), u(random), u(random));
    const Vec3 lo = a.cwiseMin(b), hi = a.cwiseMax(b);
    double expected = 1;
    for (int d = 0; d < 3; ++d) expected *= std::max(0.0, std::min(hi[d], 1.0) - std::max(lo[d], 0.0));
    double sum = 0;
    for (const Corners& t : tets) sum += post::tet_box_overlap(t, lo, hi);
    EXPECT_NEAR(sum, expected, 1e-13) << "box " << lo.transpose() << " – " << hi.transpose();
  }
}

TEST(TetBoxOverlap, AVoxelGridPartitionsATetrahedron) {
  // Over voxels tiling space, the overlaps of any tetrahedron add up to its volume; a corner
  // tetrahedron x + y + z <= s inside one box is its own volume s³/6.
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    Corners t = {Vec3(u(random), u(random), u(random)), Vec3(u(random), u(random), u(random)),
                 Vec3(u(random), u(random), u(random)), Vec3(u(random), u(random), u(random))};
    double sum = 0;
    const double h = 0.3;
    for (int i = -4; i < 4; ++i)
      for (int j = -4; j < 4; ++j)
        for (int k = -4; k < 4; ++k) {
          const Vec3 lo = h * Vec3(i, j, k);
          sum += post::tet_box_overlap(t, lo, lo + Vec3::Constant(h));
        }
    EXPECT_NEAR(sum, abs_volume(t), 1e-14);
  }
  const Corners corner = {Vec3(0, 0, 0), Vec3(0.5, 0, 0), Vec3(0, 0.5, 0), Vec3(0, 0, 0.5)};
  EXPECT_NEAR(post::tet_box_overlap(corner, Vec3::Constant(-1), Vec3::Constant(1)), 0.125 / 6, 1e-16);
  EXPECT_EQ(post::tet_box_overlap(corner, Vec3::Constant(0.6), Vec3::Constant(1)), 0.0);
}

TEST(FemFill, SharesEachGrainAmongTheElementsItOverlaps) {
  // One grain in the middle of a cube split in six: the elements together hold exactly its
  // volume, each its exact part (the six are alike under the cube's symmetry: a sixth each).
  geometry::TetMesh m;
  for (const Corners& t : cube_tets()) {
    geometry::Tet tet;
    for (int k = 0; k < 4; ++k) {
      tet[std::size_t(k)] = int(m.nodes.size());
      m.nodes.push_back(1e-3 * t[std::size_t(k)]);
    }
    if ((m.nodes[tet[1]] - m.nodes[tet[0]]).cross(m.nodes[tet[2]] - m.nodes[tet[0]]).dot(m.nodes[tet[3]] - m.nodes[tet[0]]) < 0)
      std::swap(tet[2], tet[3]);
    m.tets.push_back(tet);
  }
  const double r = 0.3e-3, grain_volume = 4.0 / 3.0 * M_PI * r * r * r;
  const post::CavityShape cube{[](const Vec3& p) { return std::min(p.minCoeff(), 1e-3 - p.maxCoeff()); }, Vec3::Zero(),
                               Vec3::Constant(1e-3)};
  const post::FemFill f = post::fill_elements(m, {{Vec3::Constant(0.5e-3), r, 1.0}}, cube, 0.05e-3, 7800);
  // Binning is exact to 1e-9 of the sphere per voxel (postprocess/sphere_box.hpp), over the
  // thousand voxels it touches; sharing the binned volume among the elements adds only rounding.
  EXPECT_NEAR(f.binned_solid_m3, grain_volume, 1e-6 * grain_volume);
  EXPECT_NEAR(f.solid_volume_m3, f.binned_solid_m3, 1e-12 * grain_volume);
  EXPECT_EQ(f.outside_mesh_m3, 0.0);
  for (std::size_t e = 0; e < 6; ++e)
    EXPECT_NEAR(f.element_fraction[e] * f.element_volume[e], grain_volume / 6, 1e-3 * grain_volume / 6) << "element " << e;
  for (double phi : f.node_fraction) EXPECT_NEAR(phi, grain_volume / 1e-9, 1e-3 * grain_volume / 1e-9);
}

// The report's inverted_elements counts elements as handed over: one turned inside out (two
// corners swapped) is counted, its twin in C3D4's order is not.
TEST(TetQuality, CountsAnElementTurnedInsideOut) {
  geometry::TetMesh m;
  m.nodes = {Vec3(0, 0, 0), Vec3(1e-3, 0, 0), Vec3(0, 1e-3, 0), Vec3(0, 0, 1e-3), Vec3(0, 0, -1e-3)};
  m.tets = {{0, 1, 2, 3}, {0, 1, 2, 4}};
  EXPECT_EQ(geometry::tet_quality(m).inverted, 1u);
  m.tets[1] = {0, 2, 1, 4};
  EXPECT_EQ(geometry::tet_quality(m).inverted, 0u);
}
