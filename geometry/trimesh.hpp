#pragma once
// The plain triangle mesh every stage passes around: vertex positions in metres (SI inside the
// code) and triangles as vertex index triples, counter-clockwise seen from outside.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <string>
#include <optional>
#include <string_view>
#include <vector>

#include "core/choice.hpp"

namespace geometry {

using Vec3 = Eigen::Vector3d;
using Triangle = std::array<int, 3>;

struct TriMesh {
  std::vector<Vec3> vertices;       // [m]
  std::vector<Triangle> triangles;  // indices into vertices
};

struct Box {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = Vec3::Constant(-std::numeric_limits<double>::infinity());
  void extend(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  bool empty() const { return !(lo.array() <= hi.array()).all(); }
  Vec3 size() const { return hi - lo; }
};

Box bounding_box(const TriMesh& mesh);
// Signed volume by the divergence theorem [m³]: positive for a closed mesh oriented outward.
double signed_volume(const TriMesh& mesh);

// The pieces of the mesh that share no vertex, each with its own vertices, in the order of their
// first triangles: the separate bodies of a part (the gears of a gear set).
std::vector<TriMesh> separate_bodies(const TriMesh& mesh);

// The mesh cut by the plane where coordinate `axis` (0 x, 1 y, 2 z) equals `at`: one segment per
// triangle crossed, as (u0, v0, u1, v1) in the plane's other two coordinates in order (z: x, y;
// y: x, z; x: y, z). For drawing a die's outline; a vertex on the plane counts as above it.
std::vector<std::array<double, 4>> plane_section(const TriMesh& mesh, int axis, double at);

// Length units a mesh file may declare (files store none).
enum class LengthUnit { mm, m, in };
inline constexpr std::array<diefill::Choice<LengthUnit>, 3> length_units = {
    {{"mm", LengthUnit::mm}, {"m", LengthUnit::m}, {"in", LengthUnit::in}}};
double metres_per_unit(LengthUnit unit);
inline std::string_view unit_name(LengthUnit unit) { return diefill::choice_name(length_units, unit); }
// Throws diefill::InputError naming `field` when `text` is not mm, m or in.
LengthUnit parse_unit(std::string_view text, std::string_view field);
// As parse_unit, and "auto": no unit given, to be guessed from the mesh's size (guess_unit).
std::optional<LengthUnit> parse_unit_or_auto(std::string_view text, std::string_view field);
// The unit a file most likely uses, from its largest extent in the file's own numbers: a die or
// a part is 3 mm to a metre or two across (docs/MESHES.md, "Units"). 3 or more reads as mm; 1 to 3 as
// inches (25-76 mm: a part a few inches across); less than 1 as metres (a part under a metre).
LengthUnit guess_unit(double extent_in_file_units);

}  // namespace geometry
