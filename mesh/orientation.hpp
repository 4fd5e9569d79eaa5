#pragma once
// Which way a die's opening faces (docs/ARCHITECTURE.md, "Walls as signed-distance fields"): a cavity mesh from CAD often
// lies on its side. The opening is a flat face at the mesh's extreme along one axis; the die is
// turned (a rotation, never a mirror) so that it faces +z, the table's side.
#include <array>
#include <optional>
#include <string>
#include <string_view>

#include "core/choice.hpp"
#include "geometry/trimesh.hpp"

namespace mesh {

struct Up {
  int axis = 2;  // 0 x, 1 y, 2 z
  int sign = 1;  // +1 or -1
  bool operator==(const Up&) const = default;
};

inline constexpr std::array<diefill::Choice<Up>, 6> directions = {
    {{"+z", Up{2, 1}}, {"-z", Up{2, -1}}, {"+x", Up{0, 1}}, {"-x", Up{0, -1}}, {"+y", Up{1, 1}}, {"-y", Up{1, -1}}}};

// One of the directions, or "auto" (nullopt: find it). Throws InputError naming `field`.
std::optional<Up> parse_up(std::string_view text, std::string_view field);
std::string up_name(Up up);

// Area of the faces lying flat at the mesh's extreme along `up` and facing it [m²].
double opening_area(const geometry::TriMesh& mesh, Up up);

// Area of the mesh's shadow along `axis`: the part's outline seen along it [m²].
double shadow_area(const geometry::TriMesh& mesh, int axis);

// The opening a shoe can pass over: +z when the flat faces at the top cover at least half of the
// part's shadow along z (every die made for diefill), else the extreme whose flat faces cover the
// largest share of the shadow along their axis (of two alike, the + one). Throws InputError
// naming `source` when no axis has one.
Up find_opening(const geometry::TriMesh& mesh, const std::string& source);

// Whether some extreme of the mesh along an axis has a flat face facing out: what find_opening
// needs.
bool has_flat_extreme(const geometry::TriMesh& mesh);

// +x, +y or +z, whichever the part's shadow is largest along: a part with no flat face lies
// flat in its die, the shallowest cavity (of two alike, the first).
Up lying_flat(const geometry::TriMesh& mesh);

// Where the die table meets the part (docs/INTERFACE.md, `die.parting`): at its flat opening
// (refused when it has none), at its widest section along z (the upper punch forms the part
// above it), or automatically the first when it has a flat opening and else the second.
enum class Parting { automatic, opening, widest };
inline constexpr std::array<diefill::Choice<Parting>, 3> partings = {
    {{"auto", Parting::automatic}, {"opening", Parting::opening}, {"widest", Parting::widest}}};
Parting parse_parting(std::string_view text, std::string_view field);

// Area of the section of a closed, outward surface by the plane z = height [m²]: the shoelace
// sum over the segments where its triangles cross the plane, each taken the way the section's
// boundary runs counter-clockwise seen from +z (the outward normal's turn about z).
double section_area(const geometry::TriMesh& mesh, double height);
// The height [m] of the largest section_area among levels spaced evenly through the mesh's
// height (of several alike, the highest: the most of the part below the table).
double widest_section_z(const geometry::TriMesh& mesh);

// Turns the mesh so that `up` becomes +z (a proper rotation; +z leaves it as it is).
void turn_up(geometry::TriMesh& mesh, Up up);

}  // namespace mesh
