// The FEM hand-off: CGAL's tetrahedral mesh of a die's cavity, the fill integrated onto it, and
// the round trip through CalculiX against analytic solutions (docs/INTERFACE.md, "FEM hand-off").
#include <gtest/gtest.h>

#include <fmt/core.h>

#include <numbers>
#include <random>

#include "mesh/die.hpp"
#include "mesh/orientation.hpp"
#include "mesh/shapes.hpp"
#include "mesh/tetmesh.hpp"
#include "postprocess/compaction.hpp"
#include "postprocess/fem.hpp"
#include "postprocess/sphere_box.hpp"
#include "support.hpp"

namespace {

using post::Vec3;

geometry::TriMesh bundled(const std::string& name) {
  return mesh::read_die_file(test::source_dir() / "dies" / (name + ".stl"), geometry::LengthUnit::mm).mesh;
}

double mesh_volume(const geometry::TetMesh& m) {
  double v = 0;
  for (const geometry::Tet& t : m.tets) v += geometry::tet_volume(m.nodes[t[0]], m.nodes[t[1]], m.nodes[t[2]], m.nodes[t[3]]);
  return v;
}

// The area of a surface's faces whose corners all lie at `z` or above.
template <class Nodes, class Faces>
double area_at_or_above(const Nodes& nodes, const Faces& faces, double z) {
  double area = 0;
  for (const auto& f : faces) {
    const Vec3 &a = nodes[std::size_t(f[0])], &b = nodes[std::size_t(f[1])], &c = nodes[std::size_t(f[2])];
    if (std::min({a.z(), b.z(), c.z()}) >= z) area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

// The ring meshed as the pipeline meshes it for 0.8 mm grains: elements of 1.6 mm.
const geometry::TetMesh& ring_mesh() {
  static const geometry::TetMesh m = mesh::tetrahedralise(bundled("ring"), {1.6e-3, 2e-5, 60}, "ring");
  return m;
}

// The distance from p to the segment ab.
double segment_distance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
  return (a + t * (b - a) - p).norm();
}

// A FemFill of the given element fractions on `m`.
post::FemFill fill_of(const geometry::TetMesh& m, const std::function<double(const Vec3&)>& fraction) {
  post::FemFill f;
  f.mesh = m;
  f.material_density = 7800;
  for (const geometry::Tet& t : m.tets) {
    const Vec3 centroid = 0.25 * (m.nodes[t[0]] + m.nodes[t[1]] + m.nodes[t[2]] + m.nodes[t[3]]);
    f.element_volume.push_back(geometry::tet_volume(m.nodes[t[0]], m.nodes[t[1]], m.nodes[t[2]], m.nodes[t[3]]));
    f.element_fraction.push_back(fraction(centroid));
  }
  f.node_fraction = post::average_to_nodes(f.mesh, f.element_fraction, f.element_volume);
  return f;
}

// CalculiX' messages about the deck: its log holds no warning and no error.
void expect_clean_log(const std::string& log) {
  EXPECT_EQ(log.find("WARNING"), std::string::npos) << log;
  EXPECT_EQ(log.find("ERROR"), std::string::npos) << log;
}

}  // namespace

TEST(TetMesh, RingIsMeshedWithItsVolumeAndItsRimsOnMeshEdges) {
  const geometry::TriMesh ring = bundled("ring");
  const geometry::TetMesh& m = ring_mesh();
  const geometry::TetQuality q = geometry::tet_quality(m);
  const double volume = mesh_volume(m), expected = geometry::signed_volume(ring);
  std::printf("%zu nodes, %zu elements; volume %.6g of %.6g mm³; dihedral %.1f–%.1f°, radius ratio ≥ %.3f (mean %.3f)\n",
              m.nodes.size(), m.tets.size(), volume * 1e9, expected * 1e9, q.min_dihedral_deg, q.max_dihedral_deg,
              q.min_radius_ratio, q.mean_radius_ratio);
  EXPECT_EQ(q.inverted, 0u);
  EXPECT_NEAR(volume / expected, 1.0, 0.005);
  // After perturbation and exudation the smallest dihedral angle should clear 10°, the figure
  // usually quoted for CGAL's sliver exudation (a bound this project sets; it was not checked
  // against CGAL's manual here). Measured: 12.0°.
  EXPECT_GT(q.min_dihedral_deg, 10.0);
  EXPECT_GT(q.min_radius_ratio, 0.1);

  // The rims: the ring's four circles (outer and inner, at the table and the floor) are its sharp
  // edges. Every mesh node on a protected edge lies on one of them, and every rim point is within
  // the chord's sagitta (element² / 8 R) of a protected mesh edge.
  std::vector<std::array<Vec3, 2>> rims;
  for (std::size_t t = 0; t < ring.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const Vec3 &a = ring.vertices[ring.triangles[t][k]], &b = ring.vertices[ring.triangles[t][(k + 1) % 3]];
      const bool horizontal = std::abs(a.z() - b.z()) < 1e-9;
      const bool on_rim = horizontal && (std::abs(a.z()) < 1e-9 || std::abs(a.z() + 10e-3) < 1e-9) &&
                          std::abs(a.head<2>().norm() - b.head<2>().norm()) < 1e-9 && a.head<2>().norm() > 4.9e-3;
      if (on_rim) rims.push_back({a, b});
    }
  ASSERT_GT(rims.size(), 100u);
  ASSERT_GT(m.feature_edges.size(), 40u);
  double farthest_node = 0;
  for (const auto& e : m.feature_edges)
    for (int end : e) {
      double d = 1;
      for (const auto& r : rims) d = std::min(d, segment_distance(m.nodes[end], r[0], r[1]));
      farthest_node = std::max(farthest_node, d);
    }
  EXPECT_LT(farthest_node, 1e-9) << "a protected node off the rims";
  double farthest_rim = 0;
  for (const auto& r : rims) {
    double d = 1;
    for (const auto& e : m.feature_edges) d = std::min(d, segment_distance(r[0], m.nodes[e[0]], m.nodes[e[1]]));
    farthest_rim = std::max(farthest_rim, d);
  }
  EXPECT_LT(farthest_rim, 1.6e-3 * 1.6e-3 / (8 * 5e-3)) << "a rim point away from every protected edge";
}

TEST(TetMesh, IsTheSameMeshTwice) {
  const geometry::TetMesh again = mesh::tetrahedralise(bundled("ring"), {1.6e-3, 2e-5, 60}, "ring");
  ASSERT_EQ(again.tets, ring_mesh().tets);
  ASSERT_EQ(again.nodes, ring_mesh().nodes);
}

// Two 10 mm cubes 0.1 mm apart, as the planetary gear set's gears where their teeth mesh: each
// body is meshed alone and the meshes joined, so that the gap between them does not shrink the
// elements of either (Mesh_3 keeps the protecting balls of the two bodies' edges apart). The
// joined mesh is exactly the two cubes' own meshes, nodes and elements in that order.
TEST(TetMesh, SeparateBodiesAreMeshedEachAlone) {
  const geometry::TriMesh a = mesh::box_solid(Vec3(0, 0, 0), Vec3(10e-3, 10e-3, 10e-3));
  const geometry::TriMesh b = mesh::box_solid(Vec3(10.1e-3, 0, 0), Vec3(20.1e-3, 10e-3, 10e-3));
  geometry::TriMesh both = a;
  for (geometry::Triangle t : b.triangles) {
    for (int& v : t) v += int(a.vertices.size());
    both.triangles.push_back(t);
  }
  both.vertices.insert(both.vertices.end(), b.vertices.begin(), b.vertices.end());
  const std::vector<geometry::TriMesh> bodies = geometry::separate_bodies(both);
  ASSERT_EQ(bodies.size(), 2u);
  EXPECT_EQ(bodies[1].triangles.size(), b.triangles.size());
  EXPECT_NEAR(geometry::signed_volume(bodies[1]), 1e-6, 1e-15);
  const mesh::TetMeshOptions o{4e-3, 2e-5, 60};
  const geometry::TetMesh alone_a = mesh::tetrahedralise(bodies[0], o, "a"), alone_b = mesh::tetrahedralise(bodies[1], o, "b");
  const geometry::TetMesh joined = mesh::tetrahedralise(both, o, "both");
  ASSERT_EQ(joined.tets.size(), alone_a.tets.size() + alone_b.tets.size());
  ASSERT_EQ(joined.nodes.size(), alone_a.nodes.size() + alone_b.nodes.size());
  for (std::size_t i = 0; i < alone_b.nodes.size(); ++i)
    ASSERT_EQ(joined.nodes[alone_a.nodes.size() + i], alone_b.nodes[i]) << i;
  EXPECT_NEAR(mesh_volume(joined), 2e-6, 1e-12);
}

// A 10 mm cube whose corner (10, 10, 10) mm is cut off by a chamfer 1 µm across, edges of microns
// between sharp features as on the planetary gear set's ring gear: those vertices are welded
// before meshing (they lie within the facet distance), so no element edge is that short. Unwelded,
// Mesh_3 protects the chamfer's edges and puts nodes on its three corners.
TEST(TetMesh, EdgesShorterThanTheFacetDistanceShrinkNoElement) {
  const double d = 1e-6, a = 10e-3;
  geometry::TriMesh cube;
  cube.vertices = {Vec3(0, 0, 0), Vec3(a, 0, 0), Vec3(a, a, 0), Vec3(0, a, 0), Vec3(0, 0, a), Vec3(a, 0, a),
                   Vec3(a - d, a, a), Vec3(a, a - d, a), Vec3(a, a, a - d), Vec3(0, a, a)};
  enum { O, X, XY, Y, Z, XZ, Gx, Gy, Gz, YZ };
  // Each face as a polygon counter-clockwise seen from outside, fanned from its first corner.
  const std::vector<std::vector<int>> faces = {{O, Y, XY, X},  {O, X, XZ, Z},       {O, Z, YZ, Y},  {Z, XZ, Gy, Gx, YZ},
                                               {X, XY, Gz, Gy, XZ}, {Y, YZ, Gx, Gz, XY}, {Gx, Gy, Gz}};
  for (const auto& f : faces)
    for (std::size_t k = 1; k + 1 < f.size(); ++k) cube.triangles.push_back({f[0], f[k], f[k + 1]});
  ASSERT_NEAR(geometry::signed_volume(cube), a * a * a, 1e-15) << "closed and outward";
  const geometry::TetMesh m = mesh::tetrahedralise(cube, {4e-3, 2e-5, 60}, "chamfer");
  double shortest = 1;
  for (const geometry::Tet& t : m.tets)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) shortest = std::min(shortest, (m.nodes[t[i]] - m.nodes[t[j]]).norm());
  EXPECT_GT(shortest, 1e-4);
  EXPECT_NEAR(mesh_volume(m), a * a * a, 1e-3 * a * a * a);
}

// Shared dies meshed as their pipeline runs mesh them (docs/MESHES.md, "Shared dies through the
// pipeline"): the largest grain radius, the SDF voxel and the element size of that run.
struct SharedCavity {
  const char* file;
  geometry::LengthUnit unit;
  double grain_radius_m, voxel_m, element_m;
  const char* up_in_file = nullptr;  // the way its opening faces in the file, where that is what its repair found
};
void PrintTo(const SharedCavity& c, std::ostream* os) { *os << c.file; }
class SharedCavityMesh : public ::testing::TestWithParam<SharedCavity> {};

// CalculiX refuses an element whose Jacobian determinant is under 1e-20 ("nonpositive jacobian",
// e_c3d.f: `if(xsj.lt.1.d-20)`), an absolute bound in the deck's units (SI): 6 V of a tetrahedron
// with straight edges. In their pipeline runs, the turbine blade (cut at its widest section) had
// 28 such elements, 0.2-0.5 µm across, where its surface has edges that short, and the flanged
// ring 35,117, at caps of its re-mesh 0.1 µm high (here, before the fix: 23 and 69,092).
TEST_P(SharedCavityMesh, HasNoElementCalculiXRefuses) {
  REQUIRE_SHARED_MESHES();
  const SharedCavity& c = GetParam();
  mesh::DieOptions o = mesh::die_options_for_grains(c.grain_radius_m, 0.5 * c.grain_radius_m, c.voxel_m);
  o.unit = c.unit;
  o.role = mesh::WallRole::cavity;
  const mesh::PreparedDie die = mesh::prepare_die(test::shared_meshes() / "dies" / c.file, o, std::nullopt);
  if (c.up_in_file) {
    // The flanged ring's file lacks its face at the opening: repair closes it flat, so that its
    // flat faces at the top cover at least half of the part's outline, as find_opening asks of a
    // top face (before, none lay flat there and the die was refused for it).
    EXPECT_EQ(mesh::up_name(die.up), c.up_in_file);
    EXPECT_GE(mesh::opening_area(die.cavity, mesh::Up{2, 1}), 0.5 * mesh::shadow_area(die.cavity, 2));
  }
  const double facet_distance = c.element_m / 200;
  const geometry::TetMesh m = mesh::tetrahedralise(die.cavity, {c.element_m, facet_distance, 60}, c.file);
  std::size_t refused = 0;
  double smallest = 1;
  for (const geometry::Tet& t : m.tets) {
    const double jacobian = 6 * geometry::tet_volume(m.nodes[t[0]], m.nodes[t[1]], m.nodes[t[2]], m.nodes[t[3]]);
    refused += jacobian < 1e-20;
    smallest = std::min(smallest, jacobian);
  }
  EXPECT_EQ(refused, 0u) << "of " << m.tets.size() << " elements; the smallest 6 V is " << smallest << " m³";
  // The punch presses the opening: the deck's TABLE faces lie in it, the cavity's faces in its top
  // plane, and cover most of it (along the rim, where the blade meets its cut at a shallow angle,
  // the mesher may tilt a facet out of the plane within the facet distance).
  double top = -1, top_node = -1;
  for (const Vec3& p : die.cavity.vertices) top = std::max(top, p.z());
  for (const Vec3& p : m.nodes) top_node = std::max(top_node, p.z());
  const double opening = area_at_or_above(die.cavity.vertices, die.cavity.triangles, top - 1e-12);  // a cut's rounding
  const double table = area_at_or_above(m.nodes, post::boundary_sets(m, top_node).table, -1.0);
  EXPECT_LE(table, opening * (1 + 1e-9));
  EXPECT_GT(table, 0.9 * opening) << "the punch presses the opening (with a node 1.85 nm above it, it pressed nothing)";
  // The boundary lies within the facet distance of the surface: the volume within that times its area.
  EXPECT_NEAR(mesh_volume(m), die.after.volume_m3, facet_distance * die.after.area_m2);
}

INSTANTIATE_TEST_SUITE_P(
    Pipeline, SharedCavityMesh,
    ::testing::Values(SharedCavity{"large_turbineblade_vtk_199k.ply", geometry::LengthUnit::mm, 0.453e-3, 0.25 * 0.453e-3, 1.8129e-3},
                      SharedCavity{"flanged_ring_trimesh_idler_riser.stl", geometry::LengthUnit::in, 0.9125e-3, 0.365e-3, 3.3179e-3, "-z"}));

// Mesh_3 places a flat face's nodes by its constructions: in a pipeline run on the turbine blade
// one table node lay 1.85 nm above the rest, and the table, taken as the highest node's plane,
// had no face left, so the compaction example's punch pressed nothing. The ring's table with one
// node raised that much keeps every face it had, and they cover the ring's top (to the corners
// the mesh's rim cuts off the file's 104-gons, less than 0.1 %).
TEST(FemFiles, TheTableKeepsItsFacesWhenANodeLiesNanometresAboveIt) {
  geometry::TetMesh m = ring_mesh();
  double top = -1;
  for (const Vec3& p : m.nodes) top = std::max(top, p.z());
  const std::size_t faces = post::boundary_sets(m, top).table.size();
  const auto on_top = std::find_if(m.nodes.begin(), m.nodes.end(), [&](const Vec3& p) { return p.z() == top; });
  ASSERT_NE(on_top, m.nodes.end());
  on_top->z() += 1.85e-9;
  const post::BoundarySets raised = post::boundary_sets(m, top + 1.85e-9);
  EXPECT_EQ(raised.table.size(), faces);
  const geometry::TriMesh ring = bundled("ring");
  const double opening = area_at_or_above(ring.vertices, ring.triangles, top);
  EXPECT_NEAR(area_at_or_above(m.nodes, raised.table, -1.0), opening, 1e-3 * opening);
}

namespace {

// An FCC lattice of touching spheres (cells of 0.4 mm, φ = 0.7405) in the ring's cavity, every
// sphere wholly inside it: a lattice uniform inside and a layer void of grains along every wall,
// as grain centres keep a radius from a real wall. Its solid at a point is known exactly.
struct WallLayerLattice {
  static constexpr double a = 0.4e-3, r = a * 0.35355339059327373;  // a √2 / 4
  const double ro = 10e-3 * std::cos(std::numbers::pi / 104), ri = 5e-3;  // the 104-gons' inscribed and outer radii
  const Vec3 shift = Vec3(0.013e-3, 0.029e-3, 0.05e-3);
  const std::array<Vec3, 4> basis = {Vec3(0, 0, 0), Vec3(0.5, 0.5, 0), Vec3(0.5, 0, 0.5), Vec3(0, 0.5, 0.5)};

  bool holds(const Vec3& c) const {
    const double rho = c.head<2>().norm();
    return rho > ri + r && rho < ro - r && c.z() > -10e-3 + r && c.z() < 0;
  }
  std::vector<post::Grain> grains() const {
    std::vector<post::Grain> out;
    const int cells = int(std::ceil(10.5e-3 / a));
    for (int i = -cells; i <= cells; ++i)
      for (int j = -cells; j <= cells; ++j)
        for (int k = -cells; k <= 2; ++k)
          for (const Vec3& b : basis)
            if (const Vec3 c = a * (Vec3(i, j, k) + b) + shift; holds(c)) out.push_back({c, r, 1.0});
    return out;
  }
  // Whether p lies in a sphere: the nearest sites of each sub-lattice are the corners of the cell
  // around p (a sphere reaches 0.354 of a cell).
  bool solid_at(const Vec3& p) const {
    const Vec3 q = (p - shift) / a;
    for (const Vec3& b : basis) {
      const Vec3 base = (q - b).array().floor().matrix();
      for (int corner = 0; corner < 8; ++corner) {
        const Vec3 c = a * (base + Vec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1) + b) + shift;
        if ((p - c).norm() < r && holds(c)) return true;
      }
    }
    return false;
  }
  // The ring's cavity exactly: between the two 104-gons (vertices at angle 2πk/104), under the table.
  bool in_cavity(const Vec3& p) const {
    const double sector = 2 * std::numbers::pi / 104;
    const double middle = (std::floor(std::atan2(p.y(), p.x()) / sector) + 0.5) * sector;
    const double apothem = p.x() * std::cos(middle) + p.y() * std::sin(middle);
    return apothem <= ro && apothem >= ri * std::cos(std::numbers::pi / 104) && p.z() >= -10e-3 && p.z() <= 0;
  }
};

}  // namespace

// The FEM hand-off's elements against the truth: each element's solid fraction sampled at 2,000
// random points of its part of the cavity (σ = 0.0098 for φ = 0.74), on the ring's 1.6 mm elements
// from sub-voxels of 1.4 sphere radii (a run's are half a grain radius: this is the harder case). The void layer along the walls stays in the elements there
// (an average wider than the elements, as the hand-off once took, read it as the interior: issue
// 44): elements at the side walls and at the floor read their layers' truth to 1 % on average,
// while that truth lies 7 % and 15 % below the interior's. Per element the hand-off adds at most
// 0.016 RMS to the sampling's own scatter: half of what one run's packing scatters per voxel (5.8 %
// of 0.55 between two seeds of the default ring, docs/STUDIES.md, "speed-accuracy"), so that the
// hand-off's own error stays below the noise it hands on. The elements hold the lattice's volume
// below the table to the hand-off's promise (0.5 %), measured with no correction (there is none).
TEST(FemFill, ElementsReadTheLatticeTheyHoldWallLayersIncluded) {
  const WallLayerLattice lattice;
  const double phi = std::numbers::pi / (3 * std::sqrt(2.0));
  const std::vector<post::Grain> grains = lattice.grains();
  double below_table = 0;
  for (const post::Grain& g : grains) {
    const double h = std::clamp(g.radius - g.centre.z(), 0.0, 2 * g.radius);  // the cap below z = 0
    below_table += std::numbers::pi * h * h * (3 * g.radius - h) / 3;
  }
  const mesh::PreparedDie die = mesh::prepare_die(test::source_dir() / "dies" / "ring.stl",
                                                  mesh::die_options_for_grains(0.4e-3, 0.2e-3), std::nullopt);
  const geometry::WallField walls = die.sdf.wall_field(die.solid);
  const post::CavityShape cavity{[&](const Vec3& p) { return walls.signed_distance(p); }, die.after.bbox.lo,
                                 Vec3(die.after.bbox.hi.x(), die.after.bbox.hi.y(), die.table_z)};
  const post::FemFill f = post::fill_elements(ring_mesh(), grains, cavity, 0.2e-3, 7800);
  EXPECT_NEAR(f.binned_solid_m3 / below_table, 1.0, 1e-7);  // sphere-box volumes: 1e-9 of a sphere per voxel
  EXPECT_NEAR(f.solid_volume_m3 / below_table, 1.0, 0.005);

  // Per class of element (away from the walls, at the side walls, at the floor; those at the open
  // top left out): Σ volume × fraction of the hand-off and of the truth, and the squared differences.
  struct Class {
    std::size_t count = 0;
    double volume = 0, solid = 0, truth = 0, squared_difference = 0;
  } away, side, floor;
  std::mt19937_64 random(1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  constexpr int samples = 2000;
  for (std::size_t e = 0; e < f.mesh.tets.size(); ++e) {
    const geometry::Tet& t = f.mesh.tets[e];
    double top = -1, radius_lo = 1, radius_hi = 0, bottom = 0;
    for (int n : t) {
      const Vec3& p = f.mesh.nodes[n];
      top = std::max(top, p.z()), bottom = std::min(bottom, p.z());
      radius_lo = std::min(radius_lo, p.head<2>().norm()), radius_hi = std::max(radius_hi, p.head<2>().norm());
    }
    if (top > -1e-9) continue;
    int inside = 0, solid = 0;
    for (int k = 0; k < samples; ++k) {
      std::array<double, 3> u = {unit(random), unit(random), unit(random)};
      std::sort(u.begin(), u.end());
      const Vec3 p = u[0] * f.mesh.nodes[t[0]] + (u[1] - u[0]) * f.mesh.nodes[t[1]] + (u[2] - u[1]) * f.mesh.nodes[t[2]] +
                     (1 - u[2]) * f.mesh.nodes[t[3]];
      if (!lattice.in_cavity(p)) continue;  // the chords of the inner wall reach past it
      ++inside;
      solid += lattice.solid_at(p);
    }
    const double truth = double(solid) / double(inside);
    Class& c = bottom < -9.99e-3 ? floor : radius_lo < 5.01e-3 || radius_hi > 0.999 * lattice.ro ? side : away;
    ++c.count;
    c.volume += f.element_volume[e];
    c.solid += f.element_volume[e] * f.element_fraction[e];
    c.truth += f.element_volume[e] * truth;
    c.squared_difference += (f.element_fraction[e] - truth) * (f.element_fraction[e] - truth);
  }
  const double sampling = std::sqrt(phi * (1 - phi) / samples);
  for (const auto& [name, c] : {std::pair{"away from the walls", away}, {"at the side walls", side}, {"at the floor", floor}}) {
    const double rms = std::sqrt(c.squared_difference / double(c.count));
    std::printf("%zu elements %s: mean %.4f, truth %.4f (%.4f φ); RMS difference %.4f (sampling %.4f)\n", c.count, name,
                c.solid / c.volume, c.truth / c.volume, c.truth / c.volume / phi, rms, sampling);
    EXPECT_NEAR(c.solid / c.truth, 1.0, 0.01) << name;
    EXPECT_LT(rms, std::hypot(sampling, 0.016)) << name;
  }
  std::printf("elements hold %.6f of the lattice below the table; mesh volume %.6f of the cavity\n", f.solid_volume_m3 / below_table,
              mesh_volume(ring_mesh()) / die.after.volume_m3);
  EXPECT_GT(away.count, 300u);
  EXPECT_GT(side.count, 1000u);
  EXPECT_GT(floor.count, 200u);
  EXPECT_LT(side.truth / side.volume, 0.98 * phi) << "the lattice's wall layer must be there to be kept";
  EXPECT_LT(floor.truth / floor.volume, 0.98 * phi);
}

TEST(Compaction, AUniformDiscGivesTheAnalyticPunchForce) {
  // Uniaxial strain of a uniform fill: σ_zz = M ε everywhere, so the punch force is M ε A, with
  // A the disc's cross-section (its volume over its depth); linear and quadratic elements.
  test::TempDir dir;
  const geometry::TriMesh disc = bundled("disc");
  const double depth = 10e-3, area = geometry::signed_volume(disc) / depth, phi = 0.55;
  const post::FemFill f = fill_of(mesh::tetrahedralise(disc, {2e-3, 2e-5, 60}, "disc"), [&](const Vec3&) { return phi; });
  const post::CompactionSettings s;
  const double expected = post::constrained_modulus(post::tabulated_modulus(s, phi), s.poisson_ratio) * s.axial_strain * area;
  for (const bool quadratic : {false, true}) {
    post::write_fem(f, quadratic, "uniform disc", dir.path());
    const post::CompactionResult r = post::run_compaction(f, dir.path(), s);
    expect_clean_log(r.log);
    std::printf("%s: punch force %.6g N, analytic %.6g N\n", quadratic ? "C3D10" : "C3D4", r.punch_force_n, expected);
    EXPECT_NEAR(r.punch_force_n / expected, 1.0, 0.01);
  }
}

TEST(Compaction, TwoDensityColumnStrainsAsTheInverseOfItsModuli) {
  // A 10 x 10 x 20 mm column, looser below its middle than above: in uniaxial strain both layers
  // carry the same stress, so their strains are in the inverse ratio of their constrained moduli.
  // Each layer's strain is the slope of the axial displacement over the nodes of that layer more
  // than an element from the middle (the nodes' averaged fraction blends the layers there).
  test::TempDir dir;
  const double h = 2e-3, lo_phi = 0.45, hi_phi = 0.65;
  const geometry::TetMesh m = mesh::tetrahedralise(mesh::box_solid(Vec3(0, 0, -20e-3), Vec3(10e-3, 10e-3, 0)), {h, 2e-5, 60}, "column");
  const post::FemFill f = fill_of(m, [&](const Vec3& c) { return c.z() < -10e-3 ? lo_phi : hi_phi; });
  post::write_fem(f, false, "two-density column", dir.path());
  const post::CompactionSettings s;
  const post::CompactionResult r = post::run_compaction(f, dir.path(), s);
  expect_clean_log(r.log);
  auto slope = [&](double z_lo, double z_hi) {
    double n = 0, sz = 0, su = 0, szz = 0, szu = 0;
    for (std::size_t i = 0; i < m.nodes.size(); ++i) {
      const double z = m.nodes[i].z(), u = r.node_displacement.at(i).z();
      if (z < z_lo || z > z_hi) continue;
      n += 1, sz += z, su += u, szz += z * z, szu += z * u;
    }
    return (n * szu - sz * su) / (n * szz - sz * sz);
  };
  const double strain_lo = slope(-20e-3, -10e-3 - h), strain_hi = slope(-10e-3 + h, 0.0);
  const double expected = post::constrained_modulus(post::tabulated_modulus(s, hi_phi), s.poisson_ratio) /
                          post::constrained_modulus(post::tabulated_modulus(s, lo_phi), s.poisson_ratio);
  std::printf("strain ratio %.5g, moduli ratio %.5g\n", strain_lo / strain_hi, expected);
  EXPECT_NEAR(strain_lo / strain_hi / expected, 1.0, 0.01);
}

TEST(FemFiles, AreReadByMeshioWithTheirArrays) {
  test::TempDir dir;
  const geometry::TetMesh& m = ring_mesh();
  const post::FemFill f = fill_of(m, [](const Vec3& c) { return 0.5 + 10 * c.x(); });
  for (const bool quadratic : {false, true}) {
    post::write_fem(f, quadratic, "ring", dir.path());
    const std::string script = fmt::format(
        "import meshio, numpy as np\n"
        "m = meshio.read('{}')\n"
        "cells = m.cells_dict['{}']\n"
        "phi = m.cell_data_dict['solid_fraction']['{}']\n"
        "rho = m.cell_data_dict['density_kg_m3']['{}']\n"
        "print(len(m.points), len(cells), float(np.min(phi)), float(np.max(phi)), float(np.max(abs(rho - 7800 * phi))),"
        " len(m.point_data['solid_fraction']))\n",
        (dir.path() / "fill.vtu").string(), quadratic ? "tetra10" : "tetra", quadratic ? "tetra10" : "tetra",
        quadratic ? "tetra10" : "tetra");
    std::ofstream(dir / "read.py") << script;
    const test::Run run = test::run_command("/usr/bin/python3 " + (dir / "read.py").string() + " 2>&1");
    ASSERT_EQ(run.status, 0) << run.output;
    std::istringstream in(run.output);
    std::size_t points = 0, cells = 0, point_values = 0;
    double lo = 0, hi = 0, density_error = 1;
    in >> points >> cells >> lo >> hi >> density_error >> point_values;
    EXPECT_EQ(cells, m.tets.size());
    EXPECT_EQ(points, quadratic ? post::quadratic(f).nodes.size() : m.nodes.size());
    EXPECT_EQ(point_values, points);
    EXPECT_NEAR(lo, *std::min_element(f.element_fraction.begin(), f.element_fraction.end()), 1e-8);
    EXPECT_NEAR(hi, *std::max_element(f.element_fraction.begin(), f.element_fraction.end()), 1e-8);
    EXPECT_LT(density_error, 1e-4);
  }
}
