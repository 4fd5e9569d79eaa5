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

// Area of the mesh's shadow along `axis`: the part's outline seen along it [m²].
double shadow_area(const TriMesh& mesh, int axis);

// The opening a shoe can pass over: +z when the flat faces at the top cover at least half of the
// part's shadow along z (every die made for diefill), else the extreme whose flat faces cover the
// largest share of the shadow along their axis (of two alike, the + one). Throws InputError
// naming `source` when no axis has one.
Up find_opening(const TriMesh& mesh, const std::string& source);

// Turns the mesh so that `up` becomes +z (a proper rotation; +z leaves it as it is).
void turn_up(TriMesh& mesh, Up up);

}  // namespace mesh
