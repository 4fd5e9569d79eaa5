#include "dem/walls.hpp"

#include <omp.h>

#include <limits>
#include <vector>

namespace dem {

namespace {

// A grain keeps its seeds until it is a quarter voxel beyond their cell: one resting on a face
// of the grid (on a floor a whole number of voxels high, say) would otherwise change cells at
// every step and walk afresh from the corners each time (on the 131k-triangle container of
// ../shared/bench/liggghts, a hundred triangles and more per query instead of one or two).
constexpr double cell_margin = 0.25;  // [voxels]

bool left_cell(const geometry::WallField& field, const WallCandidates& c, const Vec3& p) {
  for (int k = 0; k < 3; ++k) {
    const double into = p[k] / field.voxel - c.cell[std::size_t(k)];
    if (into < -cell_margin || into > 1 + cell_margin) return true;
  }
  return false;
}

}  // namespace

int wall_hits(const Model& model, double time, const Vec3& x, double r, WallHit* out, int capacity,
              WallCandidates* cache) {
  int count = 0;
  for (std::size_t p = 0; p < model.planes.size() && count < capacity; ++p) {
    const PlaneWall& plane = model.planes[p];
    const double d = (x - plane.point).dot(plane.normal);
    if (d >= r) continue;
    out[count++] = {std::int32_t(p), plane.normal, d, x - d * plane.normal, Vec3::Zero(), Vec3::Zero()};
  }
  for (std::size_t m = 0; m < model.meshes.size() && count < capacity; ++m) {
    const MeshWall& wall = model.meshes[m];
    const double height_above_cut = x.z() - (wall.cut_z + wall.cut_fraction * r);
    if (height_above_cut <= 0) continue;
    const bool moving = model.mesh_moves[m];
    const Vec3 local = moving ? wall.motion.to_local(time, x) : x;
    geometry::SurfacePoint minima[wall_slots_per_particle];
    WallCandidates fresh;
    WallCandidates& c = cache ? cache[m] : fresh;
    if (c.count < 0 || left_cell(*wall.field, c, local)) {
      c.cell = wall.field->cell_of(local);
      c.count = wall.field->cell_candidates(c.cell, c.triangles);
    }
    const int n = wall.field->local_minima_tracked(local, r, c.triangles, c.count, minima, wall_slots_per_particle);
    const Quat q = moving ? wall.motion.orientation(time) : Quat::Identity();
    for (int k = 0; k < n && count < capacity; ++k) {
      const Vec3 normal = moving ? Vec3(q * minima[k].normal) : minima[k].normal;
      // Overlap no deeper than the centre's height above the cut: the push fades to nothing at
      // the cut, so a grain that was passed under and rises meets no sudden force, and a grain
      // pinched at the rim is cut rather than crushed; in the bottom layer no deeper than the
      // cap, which rises with the height from a radius above the cut on (model.hpp, MeshWall).
      const double deepest = std::min(height_above_cut, wall.cut_cap * r + std::max(0.0, height_above_cut - r));
      const double distance = std::max(minima[k].distance, r - deepest);
      const Vec3 point = x - distance * normal;
      out[count++] = {std::int32_t(model.planes.size() + m), normal, distance, point,
                      moving ? wall.motion.point_velocity(time, point) : Vec3(Vec3::Zero()),
                      wall.motion.angular_velocity};
    }
  }
  return count;
}

double wall_distance(const Model& model, double time, const Vec3& x) {
  double nearest = std::numeric_limits<double>::infinity();
  for (const PlaneWall& plane : model.planes) nearest = std::min(nearest, (x - plane.point).dot(plane.normal));
  for (const MeshWall& wall : model.meshes) {
    const double d = wall.field->trilinear(wall.motion.to_local(time, x));
    if (std::abs(d) < std::abs(nearest)) nearest = d;
  }
  return nearest;
}

void collect_near_wall(const Model& model, State& s) {
  // In parallel: each thread lists the near grains of its own stretch of grains (a static
  // schedule gives thread t the t-th stretch), and the lists are joined in thread order, so that
  // the near list is ascending whatever the thread count.
  std::vector<std::vector<std::int32_t>> found(static_cast<std::size_t>(omp_get_max_threads()));
#pragma omp parallel
  {
    std::vector<std::int32_t>& mine = found[std::size_t(omp_get_thread_num())];
#pragma omp for schedule(static)
    for (std::size_t i = 0; i < s.owned(); ++i) {
      if (!s.active[i]) continue;
      const double reach = s.radius[i] + model.skin;
      bool close = false;
      for (const PlaneWall& plane : model.planes) close |= (s.x[i] - plane.point).dot(plane.normal) < reach;
      for (const MeshWall& wall : model.meshes) {
        // Trilinear values are within a voxel of the truth; beyond the band they are ± background.
        if (close) break;
        close = wall.field->trilinear(wall.motion.to_local(s.time, s.x[i])) < reach + wall.field->voxel;
      }
      if (close) mine.push_back(std::int32_t(i));
    }
  }
  Array<std::int32_t>& near = s.neighbours.near_wall;
  near.clear();
  for (const std::vector<std::int32_t>& part : found) near.insert(near.end(), part.begin(), part.end());
  s.wall_candidates.assign(near.size() * model.meshes.size(), WallCandidates{});
}

}  // namespace dem
