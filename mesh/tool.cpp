// Tool construction: the table top is triangulated around the cavity's rim with CGAL's
// constrained Delaunay triangulation, so that the tool shares the cavity's rim vertices exactly.
#include "mesh/tool.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <fmt/core.h>

#include <list>

#include "core/error.hpp"

namespace mesh {

namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
struct FaceInfo {
  int nesting = -1;
  bool in_domain() const { return nesting % 2 == 1; }
};
using Vb = CGAL::Triangulation_vertex_base_with_info_2<int, K>;
using Fbb = CGAL::Triangulation_face_base_with_info_2<FaceInfo, K>;
using Fb = CGAL::Constrained_triangulation_face_base_2<K, Fbb>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::Exact_predicates_tag>;

// Nesting level of every face: 0 outside the rectangle, +1 for each constraint crossed. The
// table is where the level is odd: inside the rectangle, outside the openings, and on islands
// (the top of a core rod inside a ring cavity).
void mark_nesting(Cdt& cdt) {
  std::list<Cdt::Edge> border;
  auto flood = [&](Cdt::Face_handle start, int level) {
    if (start->info().nesting != -1) return;
    std::list<Cdt::Face_handle> queue{start};
    while (!queue.empty()) {
      Cdt::Face_handle f = queue.front();
      queue.pop_front();
      if (f->info().nesting != -1) continue;
      f->info().nesting = level;
      for (int i = 0; i < 3; ++i) {
        Cdt::Face_handle n = f->neighbor(i);
        if (n->info().nesting != -1) continue;
        if (cdt.is_constrained(Cdt::Edge(f, i))) border.emplace_back(f, i);
        else queue.push_back(n);
      }
    }
  };
  flood(cdt.infinite_face(), 0);
  while (!border.empty()) {
    Cdt::Edge e = border.front();
    border.pop_front();
    Cdt::Face_handle n = e.first->neighbor(e.second);
    if (n->info().nesting == -1) flood(n, e.first->info().nesting + 1);
  }
}
}  // namespace

TableExtent table_around(const geometry::TriMesh& cavity, double margin) {
  const geometry::Box b = geometry::bounding_box(cavity);
  return {b.lo.x() - margin, b.lo.y() - margin, b.hi.x() + margin, b.hi.y() + margin, margin};
}

ToolMesh tool_from_cavity(const geometry::TriMesh& cavity, const TableExtent& table, const std::string& source) {
  using diefill::InputError;
  const geometry::Box box = geometry::bounding_box(cavity);
  ToolMesh out;
  out.table_z = box.hi.z();
  // Heights within a millionth of the die's size count as on the table (STL stores floats).
  const double eps = 1e-6 * box.size().norm();

  // Cavity faces on the table with an upward normal form the opening; the rest become tool
  // walls, reversed because the tool lies on the other side of them.
  geometry::TriMesh& tool = out.mesh;
  tool.vertices = cavity.vertices;
  for (const geometry::Triangle& t : cavity.triangles) {
    const geometry::Vec3& a = cavity.vertices[t[0]];
    const geometry::Vec3& b = cavity.vertices[t[1]];
    const geometry::Vec3& c = cavity.vertices[t[2]];
    const bool on_table = std::abs(a.z() - out.table_z) <= eps &&
                          std::abs(b.z() - out.table_z) <= eps &&
                          std::abs(c.z() - out.table_z) <= eps;
    if (on_table && (b - a).cross(c - a).z() > 0) {
      ++out.opening_faces;
      continue;
    }
    tool.triangles.push_back({t[0], t[2], t[1]});
  }
  if (out.opening_faces == 0)
    throw InputError(source, "top face",
                     "the cavity has no flat top face at its highest point, so powder cannot enter it",
                     "Orient the die so that the opening faces +z with its top face flat, or pass "
                     "role = \"tool\" if the mesh is the die body");
  if (table.x_min >= box.lo.x() || table.y_min >= box.lo.y() || table.x_max <= box.hi.x() ||
      table.y_max <= box.hi.y())
    throw InputError(source, "table", "the die table does not extend past the cavity",
                     "Enlarge the table (shoe travel or --table-margin)");

  // The rim: edges of the remaining walls used by one triangle only.
  std::map<std::pair<int, int>, int> edge_use;
  for (const geometry::Triangle& t : tool.triangles)
    for (int k = 0; k < 3; ++k) ++edge_use[std::minmax(t[k], t[(k + 1) % 3])];
  Cdt cdt;
  std::map<int, Cdt::Vertex_handle> handle_of;
  auto insert = [&](int index) {
    auto it = handle_of.find(index);
    if (it != handle_of.end()) return it->second;
    const geometry::Vec3& p = tool.vertices[index];
    auto h = cdt.insert(K::Point_2(p.x(), p.y()));
    h->info() = index;
    return handle_of[index] = h;
  };
  for (const auto& [edge, uses] : edge_use) {
    if (uses != 1) continue;
    if (std::abs(tool.vertices[edge.first].z() - out.table_z) > eps ||
        std::abs(tool.vertices[edge.second].z() - out.table_z) > eps)
      throw InputError(source, "boundary edges",
                       "the cavity is open below its top face (a hole in its walls)",
                       "Repair the mesh so that it is closed before it is used as a die");
    cdt.insert_constraint(insert(edge.first), insert(edge.second));
  }
  // The table rectangle and the block beneath it.
  const double z_top = out.table_z, z_bottom = box.lo.z() - table.thickness;
  const double xs[2] = {table.x_min, table.x_max}, ys[2] = {table.y_min, table.y_max};
  int corner[2][2][2];  // [x][y][top]
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k) {
        corner[i][j][k] = int(tool.vertices.size());
        tool.vertices.emplace_back(xs[i], ys[j], k ? z_top : z_bottom);
      }
  Cdt::Vertex_handle rect[4] = {insert(corner[0][0][1]), insert(corner[1][0][1]),
                                insert(corner[1][1][1]), insert(corner[0][1][1])};
  for (int i = 0; i < 4; ++i) cdt.insert_constraint(rect[i], rect[(i + 1) % 4]);
  mark_nesting(cdt);
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (!f->info().in_domain()) continue;
    geometry::Triangle t{f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()};
    tool.triangles.push_back(t);  // counter-clockwise in xy: normal +z
  }
  // Sides (outward) and bottom (normal -z) of the block.
  auto quad = [&](int a, int b, int c, int d) {
    tool.triangles.push_back({a, b, c});
    tool.triangles.push_back({a, c, d});
  };
  quad(corner[0][0][0], corner[1][0][0], corner[1][0][1], corner[0][0][1]);  // y = y_min
  quad(corner[1][0][0], corner[1][1][0], corner[1][1][1], corner[1][0][1]);  // x = x_max
  quad(corner[1][1][0], corner[0][1][0], corner[0][1][1], corner[1][1][1]);  // y = y_max
  quad(corner[0][1][0], corner[0][0][0], corner[0][0][1], corner[0][1][1]);  // x = x_min
  quad(corner[0][0][0], corner[0][1][0], corner[1][1][0], corner[1][0][0]);  // bottom
  return out;
}

}  // namespace mesh
