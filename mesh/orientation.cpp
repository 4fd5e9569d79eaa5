#include "mesh/orientation.hpp"

#include <cmath>

#include "core/error.hpp"

namespace mesh {

std::optional<Up> parse_up(std::string_view text, std::string_view field) {
  if (text == "auto") return std::nullopt;
  if (text.size() == 2 && (text[0] == '+' || text[0] == '-') && text[1] >= 'x' && text[1] <= 'z')
    return Up{text[1] - 'x', text[0] == '+' ? 1 : -1};
  throw diefill::InputError("", std::string(field), "'" + std::string(text) + "' is not a direction",
                            "Give +x, -x, +y, -y, +z, -z (the way the die's opening faces in the file) or auto");
}

std::string up_name(Up up) { return std::string(up.sign > 0 ? "+" : "-") + char('x' + up.axis); }

double opening_area(const TriMesh& mesh, Up up) {
  const Box box = bounding_box(mesh);
  const double top = up.sign > 0 ? box.hi[up.axis] : -box.lo[up.axis];
  // Within a millionth of the die's size counts as on the extreme (STL stores floats), as tool.cpp.
  const double eps = 1e-6 * box.size().norm();
  double area = 0;
  for (const Triangle& t : mesh.triangles) {
    const Vec3 &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
    const auto at_top = [&](const Vec3& p) { return std::abs(up.sign * p[up.axis] - top) <= eps; };
    if (!at_top(a) || !at_top(b) || !at_top(c)) continue;
    const Vec3 n = (b - a).cross(c - a);
    if (up.sign * n[up.axis] > 0) area += 0.5 * n.norm();
  }
  return area;
}

Up find_opening(const TriMesh& mesh, const std::string& source) {
  if (opening_area(mesh, Up{}) > 0) return Up{};
  // Two ends alike (an extruded part) to rounding: the + one, so that the choice is the same on
  // every machine; --up turns the other up.
  Up best{};
  double largest = 0;
  for (int axis = 0; axis < 3; ++axis)
    for (int sign : {1, -1})
      if (const double area = opening_area(mesh, Up{axis, sign}); area > largest * (1 + 1e-9)) largest = area, best = Up{axis, sign};
  if (largest == 0)
    throw diefill::InputError(source, "top face",
                              "the cavity has no flat face at its extreme along any axis, so powder cannot enter it",
                              "Give a cavity with a flat opening (the part's top face), or pass role = \"tool\" if the "
                              "mesh is the die body");
  return best;
}

void turn_up(TriMesh& mesh, Up up) {
  // The up axis becomes z; another axis takes its place, with a sign that keeps the turn proper.
  for (Vec3& p : mesh.vertices) {
    const Vec3 q = p;
    if (up.axis == 2) p = up.sign > 0 ? q : Vec3(q.x(), -q.y(), -q.z());
    else if (up.axis == 0) p = up.sign > 0 ? Vec3(-q.z(), q.y(), q.x()) : Vec3(q.z(), q.y(), -q.x());
    else p = up.sign > 0 ? Vec3(q.x(), -q.z(), q.y()) : Vec3(q.x(), q.z(), -q.y());
  }
}

}  // namespace mesh
