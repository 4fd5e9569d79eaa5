#include "geometry/trimesh.hpp"

#include "core/error.hpp"

namespace geometry {

Box bounding_box(const TriMesh& mesh) {
  Box box;
  for (const Vec3& v : mesh.vertices) box.extend(v);
  return box;
}

double signed_volume(const TriMesh& mesh) {
  double six_volume = 0.0;
  for (const Triangle& t : mesh.triangles) {
    const Vec3& a = mesh.vertices[t[0]];
    const Vec3& b = mesh.vertices[t[1]];
    const Vec3& c = mesh.vertices[t[2]];
    six_volume += a.dot(b.cross(c));
  }
  return six_volume / 6.0;
}

std::vector<TriMesh> separate_bodies(const TriMesh& mesh) {
  // Union-find over vertices, joined through each triangle's corners.
  std::vector<int> parent(mesh.vertices.size());
  for (std::size_t v = 0; v < parent.size(); ++v) parent[v] = int(v);
  const auto root = [&parent](int v) {
    while (parent[std::size_t(v)] != v) v = parent[std::size_t(v)] = parent[std::size_t(parent[std::size_t(v)])];
    return v;
  };
  for (const Triangle& t : mesh.triangles) {
    parent[std::size_t(root(t[1]))] = root(t[0]);
    parent[std::size_t(root(t[2]))] = root(t[0]);
  }
  std::vector<int> body_of_root(mesh.vertices.size(), -1), local(mesh.vertices.size(), -1);
  std::vector<TriMesh> bodies;
  for (const Triangle& t : mesh.triangles) {
    int& body = body_of_root[std::size_t(root(t[0]))];
    if (body < 0) body = int(bodies.size()), bodies.emplace_back();
    TriMesh& b = bodies[std::size_t(body)];
    Triangle mapped{};
    for (int k = 0; k < 3; ++k) {
      int& index = local[std::size_t(t[std::size_t(k)])];
      if (index < 0) index = int(b.vertices.size()), b.vertices.push_back(mesh.vertices[std::size_t(t[std::size_t(k)])]);
      mapped[std::size_t(k)] = index;
    }
    b.triangles.push_back(mapped);
  }
  return bodies;
}

std::vector<std::array<double, 4>> plane_section(const TriMesh& mesh, int axis, double at) {
  const int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
  std::vector<std::array<double, 4>> segments;
  for (const Triangle& t : mesh.triangles) {
    std::array<double, 4> segment{};
    int ends = 0;
    for (int e = 0; e < 3; ++e) {
      const Vec3& a = mesh.vertices[std::size_t(t[std::size_t(e)])];
      const Vec3& b = mesh.vertices[std::size_t(t[std::size_t((e + 1) % 3)])];
      const double sa = a[axis] - at, sb = b[axis] - at;
      if ((sa >= 0) == (sb >= 0)) continue;
      const Vec3 p = a + (b - a) * (sa / (sa - sb));
      segment[std::size_t(2 * ends)] = p[u];
      segment[std::size_t(2 * ends + 1)] = p[v];
      ++ends;
    }
    if (ends == 2) segments.push_back(segment);
  }
  return segments;
}

double metres_per_unit(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::mm: return 1e-3;
    case LengthUnit::m: return 1.0;
    case LengthUnit::in: return 0.0254;
  }
  return 1.0;
}

LengthUnit parse_unit(std::string_view text, std::string_view field) {
  if (text == "inch") return LengthUnit::in;
  if (const auto unit = diefill::find_choice(length_units, text)) return *unit;
  throw diefill::InputError("", std::string(field), "unknown length unit '" + std::string(text) + "'",
                            "Use " + diefill::choice_list(length_units));
}

std::optional<LengthUnit> parse_unit_or_auto(std::string_view text, std::string_view field) {
  if (text == "auto") return std::nullopt;
  try {
    return parse_unit(text, field);
  } catch (const diefill::InputError&) {
    throw diefill::InputError("", std::string(field), "unknown length unit '" + std::string(text) + "'",
                              "Use " + diefill::choice_list(length_units) + ", or auto (guessed from the mesh's size)");
  }
}

LengthUnit guess_unit(double extent_in_file_units) {
  if (extent_in_file_units >= 3.0) return LengthUnit::mm;
  if (extent_in_file_units >= 1.0) return LengthUnit::in;
  return LengthUnit::m;
}

}  // namespace geometry
