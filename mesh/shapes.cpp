#include "mesh/shapes.hpp"

#include <cmath>
#include <numbers>
#include <vector>

#include "core/error.hpp"

namespace mesh {

namespace {
constexpr double pi = std::numbers::pi;

// Quad strip between two outlines of n vertices a and b. Unflipped, the normal is the tangent
// (counter-clockwise about z) crossed with b - a: away from the axis for a wall from a below to
// b above, and -z for an annulus from a inside to b outside.
void add_strip(geometry::TriMesh& m, int a, int b, int n, bool flip) {
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    if (!flip) {
      m.triangles.push_back({a + i, a + j, b + j});
      m.triangles.push_back({a + i, b + j, b + i});
    } else {
      m.triangles.push_back({a + i, b + j, a + j});
      m.triangles.push_back({a + i, b + i, b + j});
    }
  }
}

// Fan from a centre vertex over a circle; `up` gives a normal along +z.
void add_fan(geometry::TriMesh& m, int centre, int ring, int n, bool up) {
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    if (up) m.triangles.push_back({centre, ring + i, ring + j});
    else m.triangles.push_back({centre, ring + j, ring + i});
  }
}
// A cavity whose outline (counter-clockwise, star-shaped about the z axis: its polar angle rises
// along it) is extruded from z = -depth to the table at z = 0: caps fanned from the axis, each
// side segment one full-height quad.
geometry::TriMesh extruded_cavity(const std::vector<Eigen::Vector2d>& outline, double depth) {
  geometry::TriMesh m;
  const int n = int(outline.size());
  for (const double z : {-depth, 0.0})
    for (const Eigen::Vector2d& p : outline) m.vertices.emplace_back(p.x(), p.y(), z);
  const int bottom = 0, top = n;
  add_strip(m, bottom, top, n, false);
  const int top_centre = int(m.vertices.size());
  m.vertices.emplace_back(0.0, 0.0, 0.0);
  const int bottom_centre = int(m.vertices.size());
  m.vertices.emplace_back(0.0, 0.0, -depth);
  add_fan(m, top_centre, top, n, true);
  add_fan(m, bottom_centre, bottom, n, false);
  return m;
}

// A cavity between an outer and an inner outline of as many points, each point of one at the
// polar angle of the same point of the other (both counter-clockwise and star-shaped about the z
// axis), extruded from z = -depth to the table at z = 0: the part of a hub around a core rod.
geometry::TriMesh extruded_annulus(const std::vector<Eigen::Vector2d>& outer, const std::vector<Eigen::Vector2d>& inner, double depth) {
  geometry::TriMesh m;
  const int n = int(outer.size());
  const auto add_outline = [&](const std::vector<Eigen::Vector2d>& outline, double z) {
    const int first = int(m.vertices.size());
    for (const Eigen::Vector2d& p : outline) m.vertices.emplace_back(p.x(), p.y(), z);
    return first;
  };
  const int outer_bottom = add_outline(outer, -depth), outer_top = add_outline(outer, 0.0);
  add_strip(m, outer_bottom, outer_top, n, false);  // normals away from the axis
  const int inner_bottom = add_outline(inner, -depth), inner_top = add_outline(inner, 0.0);
  add_strip(m, inner_bottom, inner_top, n, true);      // normals towards the axis
  add_strip(m, inner_top, outer_top, n, true);         // top annulus, normal +z
  add_strip(m, inner_bottom, outer_bottom, n, false);  // floor annulus, normal -z
  return m;
}

std::vector<Eigen::Vector2d> circle_outline(double radius, int n) {
  std::vector<Eigen::Vector2d> out;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * pi * i / n;
    out.emplace_back(radius * std::cos(a), radius * std::sin(a));
  }
  return out;
}

// A straight-sided spline shaft's outline (ISO 14): `teeth` keys of `width` between the minor
// and the major diameter. Arcs are cut at most `step` radians apart, so that a circle sampled at
// the same polar angles (extruded_annulus) keeps its chord error small.
std::vector<Eigen::Vector2d> spline_outline(int teeth, double minor_diameter, double major_diameter, double width, double step) {
  const double r_minor = 0.5 * minor_diameter, r_major = 0.5 * major_diameter, half = 0.5 * width;
  const double at_root = std::asin(half / r_minor), at_tip = std::asin(half / r_major);
  const auto polar = [](double r, double a) { return Eigen::Vector2d(r * std::cos(a), r * std::sin(a)); };
  // Along a flank (a line at `side` half widths from the tooth's axis) the polar angle rises.
  const auto flank = [&](double centre, double side, std::vector<Eigen::Vector2d>& out, bool outward) {
    constexpr int points = 3;
    const double t0 = std::sqrt(r_minor * r_minor - half * half), t1 = std::sqrt(r_major * r_major - half * half);
    for (int i = 0; i < points; ++i) {
      const double t = outward ? t0 + (t1 - t0) * i / (points - 1) : t1 - (t1 - t0) * i / (points - 1);
      out.push_back(polar(std::hypot(t, half), centre + std::atan2(side * half, t)));
    }
  };
  const auto arc = [&](double r, double from, double to, std::vector<Eigen::Vector2d>& out) {
    const int cuts = std::max(1, int(std::ceil((to - from) / step)));
    for (int i = 1; i < cuts; ++i) out.push_back(polar(r, from + (to - from) * i / cuts));
  };
  std::vector<Eigen::Vector2d> out;
  for (int k = 0; k < teeth; ++k) {
    const double centre = 2 * pi * k / teeth;
    flank(centre, -1, out, true);
    arc(r_major, centre - at_tip, centre + at_tip, out);
    flank(centre, 1, out, false);
    arc(r_minor, centre + at_root, centre + 2 * pi / teeth - at_root, out);
  }
  return out;
}

// The circle of `radius` at the polar angles of `outline`'s points.
std::vector<Eigen::Vector2d> circle_through_angles(double radius, const std::vector<Eigen::Vector2d>& outline) {
  std::vector<Eigen::Vector2d> out;
  for (const Eigen::Vector2d& p : outline) out.push_back(radius * p.normalized());
  return out;
}

// An involute spur gear's outline: 20° pressure angle, addendum one module, dedendum 1.25
// modules (ISO 53). Below the base circle each flank runs straight to the root circle, a little
// aside so that the polar angle keeps rising.
std::vector<Eigen::Vector2d> gear_outline(int teeth, double module) {
  const double pressure = 20.0 * pi / 180, pitch = 0.5 * module * teeth, base = pitch * std::cos(pressure);
  const double tip = pitch + module, root = pitch - 1.25 * module;
  const auto involute = [](double a) { return std::tan(a) - a; };
  // The tooth's half angle at radius r (r from the base circle to the tip).
  const auto half_angle = [&](double r) {
    return pi / (2 * teeth) + involute(pressure) - involute(std::acos(std::min(1.0, base / r)));
  };
  const double aside = 0.01, at_base = half_angle(base) + aside;
  const auto polar = [](double r, double a) { return Eigen::Vector2d(r * std::cos(a), r * std::sin(a)); };
  constexpr int flank_points = 9, tip_points = 2, root_points = 4;
  std::vector<Eigen::Vector2d> out;
  for (int k = 0; k < teeth; ++k) {
    const double centre = 2 * pi * k / teeth;
    out.push_back(polar(root, centre - at_base));
    for (int i = 0; i < flank_points; ++i) {
      const double r = base + (tip - base) * i / (flank_points - 1);
      out.push_back(polar(r, centre - half_angle(r)));
    }
    for (int i = 1; i <= tip_points; ++i)
      out.push_back(polar(tip, centre - half_angle(tip) + 2 * half_angle(tip) * i / (tip_points + 1)));
    for (int i = flank_points - 1; i >= 0; --i) {
      const double r = base + (tip - base) * i / (flank_points - 1);
      out.push_back(polar(r, centre + half_angle(r)));
    }
    out.push_back(polar(root, centre + at_base));
    const double gap = 2 * pi / teeth - 2 * at_base;
    for (int i = 1; i <= root_points; ++i) out.push_back(polar(root, centre + at_base + gap * i / (root_points + 1)));
  }
  return out;
}
}  // namespace

double chord_error(double radius, int segments) {
  return radius * (1.0 - std::cos(pi / segments));
}

int circle_segments(double radius, double chord_tolerance) {
  int n = int(std::ceil(pi / std::acos(1.0 - chord_tolerance / radius)));
  return std::max(8, (n + 7) / 8 * 8);
}

geometry::TriMesh ring_cavity(double outer_diameter, double inner_diameter, double depth,
                              double chord_tolerance) {
  const double ro = outer_diameter / 2, ri = inner_diameter / 2;
  const int n = circle_segments(ro, chord_tolerance);
  if (ri <= 0) return extruded_cavity(circle_outline(ro, n), depth);
  return extruded_annulus(circle_outline(ro, n), circle_outline(ri, n), depth);
}

geometry::TriMesh box_solid(const geometry::Vec3& lo, const geometry::Vec3& hi) {
  geometry::TriMesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
  // Each face as a quad, counter-clockwise seen from outside.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.push_back({q[0], q[1], q[2]});
    m.triangles.push_back({q[0], q[2], q[3]});
  }
  return m;
}

geometry::TriMesh revolved_solid(const std::vector<std::array<double, 2>>& profile, int segments) {
  geometry::TriMesh m;
  const int n = int(profile.size());
  for (const auto& [r, z] : profile)
    for (int j = 0; j < segments; ++j) {
      const double theta = 2 * std::numbers::pi * j / segments;
      m.vertices.emplace_back(r * std::cos(theta), r * std::sin(theta), z);
    }
  // Each profile edge turned through one step is a quad; with the profile counter-clockwise in
  // (r, z), (a, d, c) and (a, c, b) face outward.
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < segments; ++j) {
      const int next_j = (j + 1) % segments, next_i = (i + 1) % n;
      const int a = i * segments + j, b = next_i * segments + j, c = next_i * segments + next_j, d = i * segments + next_j;
      m.triangles.push_back({a, d, c});
      m.triangles.push_back({a, c, b});
    }
  return m;
}

geometry::TriMesh shoe_solid(double inner_length, double inner_width, double height, double thickness) {
  // A rectangular tube: outer and inner rectangles at z = 0 and z = height, joined.
  geometry::TriMesh m;
  const double ix = inner_length / 2, iy = inner_width / 2, ox = ix + thickness, oy = iy + thickness;
  const double xs[2][4] = {{-ox, ox, ox, -ox}, {-ix, ix, ix, -ix}};
  const double ys[2][4] = {{-oy, -oy, oy, oy}, {-iy, -iy, iy, iy}};
  auto vertex = [&](int ring, int corner, int top) { return ring * 8 + top * 4 + corner; };
  for (int ring = 0; ring < 2; ++ring)
    for (int top = 0; top < 2; ++top)
      for (int c = 0; c < 4; ++c) m.vertices.emplace_back(xs[ring][c], ys[ring][c], top ? height : 0.0);
  auto quad = [&](int a, int b, int c, int d) {
    m.triangles.push_back({a, b, c});
    m.triangles.push_back({a, c, d});
  };
  for (int c = 0; c < 4; ++c) {
    const int n = (c + 1) % 4;
    quad(vertex(0, c, 0), vertex(0, n, 0), vertex(0, n, 1), vertex(0, c, 1));  // outer side, facing out
    quad(vertex(1, n, 0), vertex(1, c, 0), vertex(1, c, 1), vertex(1, n, 1));  // inner side, facing in
    quad(vertex(0, c, 1), vertex(0, n, 1), vertex(1, n, 1), vertex(1, c, 1));  // top rim, +z
    quad(vertex(0, n, 0), vertex(0, c, 0), vertex(1, c, 0), vertex(1, n, 0));  // bottom rim, -z
  }
  return m;
}

std::vector<std::string> bundled_die_names() { return {"disc", "ring"}; }
std::vector<std::string> generated_die_names() { return {"disc", "gear", "ring", "slot", "spline"}; }

geometry::TriMesh bundled_die(const std::string& name) {
  // Chord error 5 µm: half the 0.01 mm the dies must meet.
  constexpr double chord = 5e-6;
  if (name == "disc") return ring_cavity(20e-3, 0.0, 10e-3, chord);
  if (name == "ring") return ring_cavity(20e-3, 10e-3, 10e-3, chord);
  if (name == "gear") return extruded_cavity(gear_outline(24, 1.2e-3), 8e-3);
  if (name == "slot") return extruded_cavity({{-5e-3, -0.6e-3}, {5e-3, -0.6e-3}, {5e-3, 0.6e-3}, {-5e-3, 0.6e-3}}, 8e-3);
  if (name == "spline") {
    // Arcs cut every 3°: the Ø24 mm outer circle's chord error 4 µm, under the 5 µm above.
    const std::vector<Eigen::Vector2d> core = spline_outline(6, 11e-3, 14e-3, 3e-3, 3.0 * pi / 180);
    return extruded_annulus(circle_through_angles(12e-3, core), core, 8e-3);
  }
  throw diefill::InputError("", "die", "unknown bundled die '" + name + "'", "Use disc, ring, gear, slot or spline");
}

}  // namespace mesh
