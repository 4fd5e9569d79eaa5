#include "mesh/orientation.hpp"

#include <algorithm>
#include <array>
#include <optional>
#include <cmath>
#include <vector>

#include "core/error.hpp"

namespace mesh {

namespace {
// Cells of the shadow's grid along the longer side: its area to about half a percent.
constexpr int shadow_cells = 256;
// A flat top face that leaves more than half of the part's outline closed is no opening (a tooth
// tip, a boss's end face: the shared 8-tooth gear and flanged ring, 3 % and 9 % of theirs); the
// slot die's 1.2 mm opening is the whole of its outline. The project's choice, docs/MESHES.md "Dies".
constexpr double min_top_open_share = 0.5;
// Levels the widest section is sought among: a section to 1/256 of the part's height.
constexpr int section_levels = 256;
}  // namespace

std::optional<Up> parse_up(std::string_view text, std::string_view field) {
  if (text == "auto") return std::nullopt;
  if (const auto up = diefill::find_choice(directions, text)) return *up;
  throw diefill::InputError("", std::string(field), "'" + std::string(text) + "' is not a direction",
                            "Give +x, -x, +y, -y, +z, -z (the way the die's opening faces in the file) or auto");
}

std::string up_name(Up up) { return std::string(diefill::choice_name(directions, up)); }

double opening_area(const geometry::TriMesh& mesh, Up up) {
  const geometry::Box box = geometry::bounding_box(mesh);
  const double top = up.sign > 0 ? box.hi[up.axis] : -box.lo[up.axis];
  // Within a millionth of the die's size counts as on the extreme (STL stores floats), as tool.cpp.
  const double eps = 1e-6 * box.size().norm();
  double area = 0;
  for (const geometry::Triangle& t : mesh.triangles) {
    const geometry::Vec3 &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
    const auto at_top = [&](const geometry::Vec3& p) { return std::abs(up.sign * p[up.axis] - top) <= eps; };
    if (!at_top(a) || !at_top(b) || !at_top(c)) continue;
    const geometry::Vec3 n = (b - a).cross(c - a);
    if (up.sign * n[up.axis] > 0) area += 0.5 * n.norm();
  }
  return area;
}

double shadow_area(const geometry::TriMesh& mesh, int axis) {
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  const geometry::Box box = geometry::bounding_box(mesh);
  const double h = std::max(box.size()[u], box.size()[v]) / shadow_cells;
  if (!(h > 0)) return 0;
  const int nu = int(std::ceil(box.size()[u] / h)) + 1, nv = int(std::ceil(box.size()[v] / h)) + 1;
  std::vector<char> covered(std::size_t(nu) * std::size_t(nv), 0);
  for (const geometry::Triangle& t : mesh.triangles) {
    const Eigen::Vector2d a(mesh.vertices[t[0]][u], mesh.vertices[t[0]][v]), b(mesh.vertices[t[1]][u], mesh.vertices[t[1]][v]),
        c(mesh.vertices[t[2]][u], mesh.vertices[t[2]][v]);
    const auto cross = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& r) {
      return (q - p).x() * (r - p).y() - (q - p).y() * (r - p).x();
    };
    const double twice_area = cross(a, b, c);
    if (twice_area == 0) continue;  // seen edge-on: its neighbours cast its shadow
    const Eigen::Vector2d lo = a.cwiseMin(b).cwiseMin(c), hi = a.cwiseMax(b).cwiseMax(c);
    const int i0 = std::max(0, int(std::ceil((lo.x() - box.lo[u]) / h - 0.5))), i1 = std::min(nu - 1, int((hi.x() - box.lo[u]) / h - 0.5));
    const int j0 = std::max(0, int(std::ceil((lo.y() - box.lo[v]) / h - 0.5))), j1 = std::min(nv - 1, int((hi.y() - box.lo[v]) / h - 0.5));
    for (int i = i0; i <= i1; ++i)
      for (int j = j0; j <= j1; ++j) {
        const Eigen::Vector2d p(box.lo[u] + (i + 0.5) * h, box.lo[v] + (j + 0.5) * h);
        const double s = twice_area > 0 ? 1 : -1;
        if (s * cross(a, b, p) >= 0 && s * cross(b, c, p) >= 0 && s * cross(c, a, p) >= 0)
          covered[std::size_t(i) * std::size_t(nv) + std::size_t(j)] = 1;
      }
  }
  return double(std::count(covered.begin(), covered.end(), 1)) * h * h;
}

Up find_opening(const geometry::TriMesh& mesh, const std::string& source) {
  // How much of the part's outline along the axis a shoe passing over that face reaches; each
  // axis's shadow rasterised once (both of its ends share it), and only where a face asks.
  std::array<std::optional<double>, 3> shadows;
  const auto open_share = [&](Up up, double area) {
    std::optional<double>& shadow = shadows[std::size_t(up.axis)];
    if (!shadow) shadow = shadow_area(mesh, up.axis);
    return *shadow > 0 ? area / *shadow : 0.0;
  };
  if (const double top = opening_area(mesh, Up{}); top > 0 && open_share(Up{}, top) >= min_top_open_share) return Up{};
  // Two ends alike (an extruded part) to rounding: the + one, so that the choice is the same on
  // every machine; --up turns the other up.
  Up best{};
  double largest = 0, best_share = 0;
  for (int axis = 0; axis < 3; ++axis)
    for (int sign : {1, -1}) {
      const Up up{axis, sign};
      const double area = opening_area(mesh, up);
      if (area == 0) continue;
      const double share = open_share(up, area);
      if (share > best_share * (1 + 1e-9) || (share >= best_share * (1 - 1e-9) && area > largest * (1 + 1e-9)))
        best_share = share, largest = area, best = up;
    }
  if (largest == 0)
    throw diefill::InputError(source, "top face",
                              "the cavity has no flat face at its extreme along any axis, so powder cannot enter it",
                              "Give a cavity with a flat opening (the part's top face), set die.parting = \"auto\" to cut "
                              "it at its widest section, or pass role = \"tool\" if the mesh is the die body");
  return best;
}

bool has_flat_extreme(const geometry::TriMesh& mesh) {
  for (int axis = 0; axis < 3; ++axis)
    for (int sign : {1, -1})
      if (opening_area(mesh, Up{axis, sign}) > 0) return true;
  return false;
}

Up lying_flat(const geometry::TriMesh& mesh) {
  Up best{};
  double largest = -1;
  for (int axis = 0; axis < 3; ++axis)
    if (const double shadow = shadow_area(mesh, axis); shadow > largest * (1 + 1e-9)) largest = shadow, best = Up{axis, 1};
  return best;
}

Parting parse_parting(std::string_view text, std::string_view field) {
  if (const auto parting = diefill::find_choice(partings, text)) return *parting;
  throw diefill::InputError("", std::string(field), "'" + std::string(text) + "' is not a parting",
                            "Give opening (the table at the part's flat face), widest (at its widest section) or auto");
}

double section_area(const geometry::TriMesh& mesh, double height) {
  double twice_area = 0;
  for (const geometry::Triangle& t : mesh.triangles) {
    const geometry::Vec3 &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
    // The crossings of the edges whose ends lie on either side (an end on the plane counts as above).
    std::array<geometry::Vec3, 2> crossing;
    int found = 0;
    for (const auto& [p, q] : {std::pair{&a, &b}, std::pair{&b, &c}, std::pair{&c, &a}})
      if (((*p).z() < height) != ((*q).z() < height) && found < 2) {
        const double s = (height - p->z()) / (q->z() - p->z());
        crossing[std::size_t(found++)] = *p + s * (*q - *p);
      }
    if (found < 2) continue;
    const geometry::Vec3 along = geometry::Vec3::UnitZ().cross((b - a).cross(c - a));
    if ((crossing[1] - crossing[0]).dot(along) < 0) std::swap(crossing[0], crossing[1]);
    twice_area += crossing[0].x() * crossing[1].y() - crossing[1].x() * crossing[0].y();
  }
  return 0.5 * twice_area;
}

double widest_section_z(const geometry::TriMesh& mesh) {
  const geometry::Box box = geometry::bounding_box(mesh);
  double best_z = box.hi.z(), largest = -1;
  for (int level = section_levels - 1; level >= 0; --level) {
    const double z = box.lo.z() + (level + 0.5) / section_levels * box.size().z();
    if (const double area = section_area(mesh, z); area > largest * (1 + 1e-9)) largest = area, best_z = z;
  }
  return best_z;
}

void turn_up(geometry::TriMesh& mesh, Up up) {
  // The up axis becomes z; another axis takes its place, with a sign that keeps the turn proper.
  for (geometry::Vec3& p : mesh.vertices) {
    const geometry::Vec3 q = p;
    if (up.axis == 2) p = up.sign > 0 ? q : geometry::Vec3(q.x(), -q.y(), -q.z());
    else if (up.axis == 0) p = up.sign > 0 ? geometry::Vec3(-q.z(), q.y(), q.x()) : geometry::Vec3(q.z(), q.y(), -q.x());
    else p = up.sign > 0 ? geometry::Vec3(q.x(), -q.z(), q.y()) : geometry::Vec3(q.x(), q.z(), -q.y());
  }
}

}  // namespace mesh
