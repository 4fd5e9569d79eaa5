#pragma once
// A die mesh is read as the cavity (the part's shape, its top face on the die table). The solid
// the powder meets is the tool: the table half-space minus the cavity. This builds that tool as
// a closed mesh over a finite table, so that its signed distance is exact at the rim edges too.
#include <string>

#include "geometry/trimesh.hpp"

namespace mesh {

struct TableExtent {
  double x_min, y_min, x_max, y_max;  // [m] the table rectangle, must contain the cavity opening
  double thickness;                   // [m] of tool below the cavity floor
};

struct ToolMesh {
  geometry::TriMesh mesh;  // closed, outward
  double table_z = 0.0;    // [m] height of the die table (the cavity's top face)
  std::size_t opening_faces = 0;  // cavity faces removed to open it at the table
};

// The table is the cavity's highest z; the faces lying there (normal +z) are its opening.
// Throws InputError naming `source` when the cavity has no flat top face or the table does not
// contain the opening.
ToolMesh tool_from_cavity(const geometry::TriMesh& cavity, const TableExtent& table, const std::string& source);

// A table rectangle `margin` wider than the cavity on every side.
TableExtent table_around(const geometry::TriMesh& cavity, double margin);

}  // namespace mesh
