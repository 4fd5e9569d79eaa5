// Exact union of intersecting closed shells by corefinement (CGAL PMP), in its own translation
// unit: corefinement is the heaviest CGAL header the project uses.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>

#include "core/log.hpp"
#include "mesh/cgal_ops.hpp"

namespace mesh::detail {

namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;

bool union_in_this_process(const TriMesh& closed_shells, TriMesh& out) {
  std::vector<Point> points;
  for (const Vec3& v : closed_shells.vertices) points.emplace_back(v.x(), v.y(), v.z());
  std::vector<std::array<std::size_t, 3>> faces;
  for (const Triangle& t : closed_shells.triangles)
    faces.push_back({std::size_t(t[0]), std::size_t(t[1]), std::size_t(t[2])});
  SurfaceMesh all;
  if (!PMP::is_polygon_soup_a_polygon_mesh(faces)) {
    diefill::log::debug("union: the surface is not a polygon mesh");
    return false;
  }
  PMP::polygon_soup_to_polygon_mesh(points, faces, all);
  std::vector<SurfaceMesh> shells;
  PMP::split_connected_components(all, shells);
  for (SurfaceMesh& s : shells) {
    if (!CGAL::is_closed(s) || PMP::does_self_intersect(s)) {
      diefill::log::debug("union: a shell of {} faces is {}", s.number_of_faces(),
                          CGAL::is_closed(s) ? "self-intersecting" : "open");
      return false;
    }
    // Corefinement's other preconditions, unchecked in a release build of CGAL (a degenerate
    // face in 3DSMaxExport.stl crashed it): no zero-area faces.
    std::vector<SurfaceMesh::Face_index> degenerate;
    PMP::degenerate_faces(s, std::back_inserter(degenerate));
    if (!degenerate.empty()) {
      diefill::log::debug("union: a shell has {} degenerate faces", degenerate.size());
      return false;
    }
    if (!PMP::is_outward_oriented(s)) PMP::reverse_face_orientations(s);
  }
  // Fold the shells into one; shells that do not touch the result are kept as they are by the
  // union as well (a union of disjoint solids is their juxtaposition).
  SurfaceMesh result = shells.front();
  for (std::size_t i = 1; i < shells.size(); ++i) {
    SurfaceMesh next;
    if (!PMP::corefine_and_compute_union(result, shells[i], next)) {
      diefill::log::debug("union: corefinement failed at shell {} of {}", i, shells.size());
      return false;
    }
    result = std::move(next);
  }
  out = TriMesh{};
  std::vector<int> index(result.number_of_vertices() + result.number_of_removed_vertices(), -1);
  for (auto v : result.vertices()) {
    index[v.idx()] = int(out.vertices.size());
    const Point& p = result.point(v);
    out.vertices.emplace_back(p.x(), p.y(), p.z());
  }
  for (auto f : result.faces()) {
    Triangle t{};
    int k = 0;
    for (auto v : CGAL::vertices_around_face(result.halfedge(f), result)) t[k++] = index[v.idx()];
    out.triangles.push_back(t);
  }
  return true;
}

bool write_all(int fd, const void* data, std::size_t bytes) {
  const char* p = static_cast<const char*>(data);
  while (bytes > 0) {
    const ssize_t n = ::write(fd, p, bytes);
    if (n <= 0) return false;
    p += n, bytes -= std::size_t(n);
  }
  return true;
}

bool read_all(int fd, void* data, std::size_t bytes) {
  char* p = static_cast<char*>(data);
  while (bytes > 0) {
    const ssize_t n = ::read(fd, p, bytes);
    if (n <= 0) return false;
    p += n, bytes -= std::size_t(n);
  }
  return true;
}

}  // namespace

// Corefinement runs in a child process: CGAL checks its preconditions only in debug builds, and
// some meshes that pass every check we can make still crash it (3DSMaxExport.stl of the shared
// broken meshes). A crash there must cost the union, not the user's run.
bool union_of_shells(const TriMesh& closed_shells, TriMesh& out) {
  int fds[2];
  if (::pipe(fds) != 0) return union_in_this_process(closed_shells, out);
  const pid_t child = ::fork();
  if (child < 0) {
    ::close(fds[0]), ::close(fds[1]);
    return union_in_this_process(closed_shells, out);
  }
  if (child == 0) {
    ::close(fds[0]);
    TriMesh united;
    const std::uint64_t ok = union_in_this_process(closed_shells, united) ? 1 : 0;
    const std::uint64_t sizes[3] = {ok, united.vertices.size(), united.triangles.size()};
    const bool sent = write_all(fds[1], sizes, sizeof sizes) &&
                      write_all(fds[1], united.vertices.data(), united.vertices.size() * sizeof(Vec3)) &&
                      write_all(fds[1], united.triangles.data(), united.triangles.size() * sizeof(Triangle));
    ::_exit(sent ? 0 : 1);
  }
  ::close(fds[1]);
  std::uint64_t sizes[3] = {0, 0, 0};
  TriMesh united;
  bool received = read_all(fds[0], sizes, sizeof sizes);
  if (received && sizes[0] == 1) {
    united.vertices.resize(sizes[1]);
    united.triangles.resize(sizes[2]);
    received = read_all(fds[0], united.vertices.data(), united.vertices.size() * sizeof(Vec3)) &&
               read_all(fds[0], united.triangles.data(), united.triangles.size() * sizeof(Triangle));
  }
  ::close(fds[0]);
  int status = 0;
  ::waitpid(child, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    diefill::log::debug("union: corefinement ended abnormally (status {})", status);
    return false;
  }
  if (!received || sizes[0] != 1) return false;
  out = std::move(united);
  return true;
}

}  // namespace mesh::detail
