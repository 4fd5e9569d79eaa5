#pragma once
// The fill on a tetrahedral mesh of the cavity, for compaction FEM (docs/INTERFACE.md, "FEM
// hand-off"): each element's solid fraction from the grains' exact volume, the nodes' by
// volume-weighted averaging, and the files compaction codes read.
#include <array>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "geometry/tet_mesh.hpp"
#include "postprocess/density.hpp"

namespace post {

struct FemFill {
  geometry::TetMesh mesh;               // linear tetrahedra [m]
  std::vector<double> element_volume;   // [m³]
  std::vector<double> element_fraction; // solid fraction of each element
  std::vector<double> node_fraction;    // volume-weighted mean of the elements around each node
  double material_density = 0;          // [kg/m³] of the grains' solid
  double solid_volume_m3 = 0;           // Σ fraction × volume over the elements
  double binned_solid_m3 = 0;           // the grains' volume below the table, exactly binned on the sub-voxels
  double outside_mesh_m3 = 0;           // of that, in sub-voxels no element reaches
  double sub_voxel_m = 0;               // the binning voxel the element values are integrated from
  std::vector<double> element_fraction_stderr;  // a seed ensemble's: of its elements' means (empty: one run)
};

// The cavity the mesh fills: the signed distance to its walls (positive inside) and its box,
// whose top is the table's plane.
struct CavityShape {
  std::function<double(const Vec3&)> distance;
  Vec3 lo, hi;
};

// Each element's solid fraction from the exact binning (sphere-box volumes on sub-voxels of edge
// `sub_voxel`, with a face on the table's plane): each sub-voxel's grain volume and cavity volume
// are shared among the elements by their exact overlaps (tetrahedron-box clipping), and each
// element's two shares divided, as the density field's wall correction divides per voxel. No
// averaging wider than a sub-voxel and no rescale: Σ fraction × volume differs from the grains'
// volume in the cavity by what the mesh's chords cut off (0.05 % of the ring's volume) and the
// sub-voxels' cavity fractions, and that difference is reported, not hidden (issue 44).
FemFill fill_elements(geometry::TetMesh mesh, const std::vector<Grain>& grains, const CavityShape& cavity, double sub_voxel,
                      double material_density);

// The volume of a tetrahedron inside the box [lo, hi] (exact up to rounding) [m³].
double tet_box_overlap(const std::array<Vec3, 4>& tet, const Vec3& lo, const Vec3& hi);

// Quadratic elements: a node at the middle of every edge (straight-sided, so the elements'
// volumes and fractions are the linear ones'). Abaqus C3D10 / VTK quadratic tetra order:
// corners 0-3, then edges 01, 12, 20, 03, 13, 23.
struct QuadraticTets {
  std::vector<Vec3> nodes;                 // the corners first, in the linear mesh's order
  std::vector<std::array<int, 10>> tets;
  std::vector<double> node_fraction;       // the edge's ends' mean at a middle node
  std::map<std::pair<int, int>, int> middle_of_edge;  // (smaller, larger corner) -> middle node
};
QuadraticTets quadratic(const FemFill& fill);

// The boundary's faces (corner nodes, 0-based) by their outward normals: TABLE (on the table's
// plane, where a top punch acts), FLOOR (facing down by more than 45°: a bottom punch or the die
// floor) and WALLS (the rest). fill.inp's node sets of the same names hold their nodes.
struct BoundarySets {
  std::vector<std::array<int, 3>> table, floor, walls;
};
BoundarySets boundary_sets(const geometry::TetMesh& mesh, double table_z);

// Node values from element values: the volume-weighted mean of the elements around each node.
std::vector<double> average_to_nodes(const geometry::TetMesh& mesh, const std::vector<double>& element_value,
                                     const std::vector<double>& element_volume);

// The hand-off files (docs/INTERFACE.md, "FEM hand-off"), atomically, into `dir`:
//   fill.inp           the mesh in the Abaqus dialect (*NODE, *ELEMENT C3D4 or C3D10, element set
//                      CAVITY and FILL_PHI<k> per 0.01 of solid fraction, node sets TABLE,
//                      FLOOR, WALLS), read alike by Abaqus and CalculiX;
//   fill_abaqus.inp    the solid fraction as field variable 1 per node and the solid fraction
//                      and density as solution-dependent state per element (Abaqus' syntax);
//   fill_calculix.inp  the same state in CalculiX' syntax (per integration point) and the
//                      nodes' solid fraction as their initial temperature;
//   fill.vtu           the elements with both as cell and point data (ParaView, meshio), and an
//                      ensemble's solid_fraction_stderr per element.
// Returns the number of nodes written (with the middle nodes of quadratic elements).
std::size_t write_fem(const FemFill& fill, bool quadratic, const std::string& heading, const std::filesystem::path& dir);

}  // namespace post
