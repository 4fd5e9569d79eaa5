#pragma once
// Which way a die's opening faces (docs/ARCHITECTURE.md, "Walls as signed-distance fields"): a cavity mesh from CAD often
// lies on its side. The opening is a flat face at the mesh's extreme along one axis; the die is
// turned (a rotation, never a mirror) so that it faces +z, the table's side.
#include <optional>
#include <string>
#include <string_view>

#include "mesh/trimesh.hpp"

namespace mesh {

struct Up {
  int axis = 2;  // 0 x, 1 y, 2 z
  int sign = 1;  // +1 or -1
  bool operator==(const Up&) const = default;
};

// "+x", "-x", "+y", "-y", "+z", "-z", or "auto" (nullopt: find it). Throws InputError naming `field`.
std::optional<Up> parse_up(std::string_view text, std::string_view field);
std::string up_name(Up up);

// Area of the faces lying flat at the mesh's extreme along `up` and facing it [m²].
double opening_area(const TriMesh& mesh, Up up);

// +z whenever a flat face lies at the top (every die made for diefill), else the axis whose
// extreme holds the largest flat face facing out (of two alike, the + one). Throws InputError naming `source` when no axis
// has one.
Up find_opening(const TriMesh& mesh, const std::string& source);

// Turns the mesh so that `up` becomes +z (a proper rotation; +z leaves it as it is).
void turn_up(TriMesh& mesh, Up up);

}  // namespace mesh
