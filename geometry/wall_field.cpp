#include "geometry/wall_field.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace geometry {

ClosestPoint closest_feature(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Ericson, Real-Time Collision Detection §5.1.5, keeping track of the Voronoi region.
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {a, Feature::vertex, 0};
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {b, Feature::vertex, 1};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return {a + ab * (d1 / (d1 - d3)), Feature::edge, 0};
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {c, Feature::vertex, 2};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return {a + ac * (d2 / (d2 - d6)), Feature::edge, 2};
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return {b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))), Feature::edge, 1};
  const double denom = 1.0 / (va + vb + vc);
  return {a + ab * (vb * denom) + ac * (vc * denom), Feature::face, 0};
}

void WallField::set_surface(const TriMesh& mesh) {
  vertices = mesh.vertices;
  triangles = mesh.triangles;
  const std::size_t nt = triangles.size(), nv = vertices.size();
  faces.resize(nt);
  vertex_normals.assign(nv, Vec3::Zero());
  std::map<std::pair<int, int>, std::pair<int, int>> edge_owner;  // directed edge -> (face, k)
  std::vector<int> degree(nv, 0);
  for (std::size_t t = 0; t < nt; ++t) {
    const Triangle& tri = triangles[t];
    WallFace& face = faces[t];
    const Vec3 n = (vertices[tri[1]] - vertices[tri[0]]).cross(vertices[tri[2]] - vertices[tri[0]]);
    face.normal = n.norm() > 0 ? Vec3(n.normalized()) : Vec3::UnitZ();
    face.vertex = tri;
    face.neighbour = {-1, -1, -1};
    for (int k = 0; k < 3; ++k) {
      face.corner[std::size_t(k)] = vertices[tri[k]];
      edge_owner[{tri[k], tri[(k + 1) % 3]}] = {int(t), k};
      ++degree[tri[k]];
      // Angle-weighted vertex pseudo-normal.
      const Vec3 e1 = (vertices[tri[(k + 1) % 3]] - vertices[tri[k]]).normalized();
      const Vec3 e2 = (vertices[tri[(k + 2) % 3]] - vertices[tri[k]]).normalized();
      vertex_normals[tri[k]] += std::acos(std::clamp(e1.dot(e2), -1.0, 1.0)) * face.normal;
    }
  }
  for (std::size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      auto it = edge_owner.find({triangles[t][(k + 1) % 3], triangles[t][k]});
      if (it != edge_owner.end()) faces[t].neighbour[std::size_t(k)] = it->second.first;
    }
  for (Vec3& n : vertex_normals)
    if (n.norm() > 0) n.normalize();
  vertex_face_offsets.assign(nv + 1, 0);
  for (std::size_t v = 0; v < nv; ++v) vertex_face_offsets[v + 1] = vertex_face_offsets[v] + degree[v];
  vertex_faces.assign(std::size_t(vertex_face_offsets[nv]), 0);
  std::vector<int> fill(vertex_face_offsets.begin(), vertex_face_offsets.end() - 1);
  for (std::size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) vertex_faces[std::size_t(fill[triangles[t][k]]++)] = int(t);
}

std::size_t WallField::memory_bytes() const {
  return vertices.size() * sizeof(Vec3) * 2 + triangles.size() * (sizeof(Triangle) + sizeof(WallFace)) +
         vertex_faces.size() * sizeof(int) + brick_of_cell.size() * 4 + distance.size() * 4 +
         closest.size() * 4;
}

bool WallField::voxel_at(int i, int j, int k, float& value, std::int32_t& triangle) const {
  const int bi = (i >> 3) - brick_min[0], bj = (j >> 3) - brick_min[1], bk = (k >> 3) - brick_min[2];
  triangle = -1;
  if (bi < 0 || bj < 0 || bk < 0 || bi >= brick_count[0] || bj >= brick_count[1] ||
      bk >= brick_count[2]) {
    value = free_band;
    return false;
  }
  const std::int32_t brick =
      brick_of_cell[(std::size_t(bi) * std::size_t(brick_count[1]) + std::size_t(bj)) *
                        std::size_t(brick_count[2]) + std::size_t(bk)];
  if (brick < 0) {
    value = brick == -2 ? -solid_band : free_band;
    return false;
  }
  const std::size_t n = std::size_t(brick) * 512 + std::size_t(((i & 7) * 8 + (j & 7)) * 8 + (k & 7));
  value = distance[n];
  triangle = closest[n];
  return triangle >= 0;
}

bool WallField::band_cell(const Vec3& p) const {
  const Vec3 lower = (p / voxel).array().floor();
  for (int c = 0; c < 8; ++c) {
    float v;
    std::int32_t t;
    if (!voxel_at(int(lower.x()) + (c >> 2 & 1), int(lower.y()) + (c >> 1 & 1),
                  int(lower.z()) + (c & 1), v, t))
      return false;
  }
  return true;
}

double WallField::trilinear(const Vec3& p) const {
  const Vec3 x = p / voxel;
  const Vec3 lower = x.array().floor();
  const Vec3 f = x - lower;
  const int i = int(lower.x()), j = int(lower.y()), k = int(lower.z());
  double value = 0.0;
  for (int c = 0; c < 8; ++c) {
    const int di = c >> 2 & 1, dj = c >> 1 & 1, dk = c & 1;
    float v;
    std::int32_t t;
    voxel_at(i + di, j + dj, k + dk, v, t);
    value += (di ? f.x() : 1 - f.x()) * (dj ? f.y() : 1 - f.y()) * (dk ? f.z() : 1 - f.z()) * v;
  }
  return value;
}

namespace {
// Normals closer than smooth_angle_deg lie on one smooth surface.
const double same_surface = std::cos(smooth_angle_deg * 3.14159265358979323846 / 180.0);
}  // namespace

SurfacePoint WallField::descend(const Vec3& p, int start, int* anchor, bool stop_at_sharp_edge) const {
  auto closest_on = [&](int t) {
    const WallFace& face = faces[std::size_t(t)];
    return closest_feature(p, face.corner[0], face.corner[1], face.corner[2]);
  };
  int current = start;
  ClosestPoint cp = closest_on(current);
  double d2 = (p - cp.point).squaredNorm();
  if (anchor) *anchor = -1;
  // Walk to a neighbouring triangle while it is strictly closer: a few steps from a voxel
  // corner's closest triangle on a coarse surface, one or none from a tracked seed.
  for (int step = 0; step < 64 && cp.feature != Feature::face; ++step) {
    int best = -1;
    ClosestPoint best_cp = cp;
    double best_d2 = d2 * (1.0 - 1e-12);
    auto consider = [&](int t) {
      if (t < 0 || t == current) return;
      const ClosestPoint c = closest_on(t);
      const double e2 = (p - c.point).squaredNorm();
      if (e2 < best_d2) best = t, best_cp = c, best_d2 = e2;
    };
    if (cp.feature == Feature::edge) {
      consider(faces[std::size_t(current)].neighbour[std::size_t(cp.index)]);
    } else {
      const int v = faces[std::size_t(current)].vertex[std::size_t(cp.index)];
      const int* fan = &vertex_faces[std::size_t(vertex_face_offsets[std::size_t(v)])];
      const int* fan_end = &vertex_faces[0] + vertex_face_offsets[std::size_t(v) + 1];
      if (stop_at_sharp_edge) {
        // Watching a surface: a closer face of it moves the walk on; failing that, the first
        // closer face across a sharp edge ends the walk. A vertex where a fine cap meets a wall
        // may hold a hundred faces, and the watch is asked at every step.
        const auto smooth = [&](int t) { return faces[std::size_t(current)].normal.dot(faces[std::size_t(t)].normal) > same_surface; };
        for (const int* f = fan; f < fan_end; ++f)
          if (smooth(*f)) consider(*f);
        for (const int* f = fan; f < fan_end && best < 0; ++f)
          if (!smooth(*f)) consider(*f);
      } else {
        for (const int* f = fan; f < fan_end; ++f) consider(*f);
      }
    }
    if (best < 0) break;
    if (anchor && *anchor < 0 && faces[std::size_t(current)].normal.dot(faces[std::size_t(best)].normal) <= same_surface) {
      *anchor = current;
      if (stop_at_sharp_edge) break;
    }
    current = best;
    cp = best_cp;
    d2 = (p - cp.point).squaredNorm();
  }

  // The result is computed from the feature alone, whichever triangle the walk reached it by, so
  // that walks from different seeds give the same minimum bit for bit (and a tracked query the
  // result of a fresh one).
  const WallFace& face = faces[std::size_t(current)];
  SurfacePoint out;
  out.point = cp.point;
  out.triangle = current;
  Vec3 pseudo_normal = face.normal;
  switch (cp.feature) {
    case Feature::face:
      out.feature = std::uint64_t(current);
      break;
    case Feature::edge: {
      // The edge from its lower-numbered vertex, whichever face the walk ended on.
      const std::size_t k = std::size_t(cp.index), k1 = std::size_t(cp.index + 1) % 3;
      const bool forward = face.vertex[k] < face.vertex[k1];
      const int a = forward ? face.vertex[k] : face.vertex[k1], b = forward ? face.vertex[k1] : face.vertex[k];
      const Vec3& from = face.corner[forward ? k : k1];
      out.feature = (1ull << 62) | (std::uint64_t(a) << 31) | std::uint64_t(b);
      const Vec3 ab = face.corner[forward ? k1 : k] - from;
      const double length2 = ab.squaredNorm();  // zero on an edge of coincident vertices
      out.point = from + (length2 > 0 ? std::clamp((p - from).dot(ab) / length2, 0.0, 1.0) : 0.0) * ab;
      const int n = face.neighbour[k];
      if (n >= 0) {
        out.triangle = std::min(current, n);
        pseudo_normal = faces[std::size_t(out.triangle)].normal + faces[std::size_t(std::max(current, n))].normal;
      }
      break;
    }
    case Feature::vertex: {
      const int v = face.vertex[std::size_t(cp.index)];
      out.feature = (2ull << 62) | std::uint64_t(v);
      out.triangle = vertex_faces[std::size_t(vertex_face_offsets[std::size_t(v)])];  // the lowest: faces are listed ascending
      pseudo_normal = vertex_normals[std::size_t(v)];
      break;
    }
  }
  const Vec3 diff = p - out.point;
  const double length = diff.norm();
  const double sign = diff.dot(pseudo_normal) >= 0 ? 1.0 : -1.0;
  out.distance = sign * length;
  out.normal = length > 1e-12 * voxel ? Vec3(sign * diff / length) : Vec3(pseudo_normal.normalized());
  return out;
}

std::array<int, 3> WallField::cell_of(const Vec3& p) const {
  const Vec3 x = p / voxel;
  return {int(std::floor(x.x())), int(std::floor(x.y())), int(std::floor(x.z()))};
}

int WallField::cell_candidates(const std::array<int, 3>& cell, std::int32_t* out) const {
  const int i = cell[0], j = cell[1], k = cell[2];
  int count = 0;
  auto add = [&](std::int32_t t) {
    if (t >= 0 && std::find(out, out + count, t) == out + count) out[count++] = t;
  };
  // Fast path: the eight corners inside one brick (about two cells in three).
  if ((i & 7) < 7 && (j & 7) < 7 && (k & 7) < 7) {
    const int bi = (i >> 3) - brick_min[0], bj = (j >> 3) - brick_min[1], bk = (k >> 3) - brick_min[2];
    if (bi < 0 || bj < 0 || bk < 0 || bi >= brick_count[0] || bj >= brick_count[1] || bk >= brick_count[2]) return 0;
    const std::int32_t brick = brick_of_cell[(std::size_t(bi) * std::size_t(brick_count[1]) + std::size_t(bj)) *
                                                 std::size_t(brick_count[2]) + std::size_t(bk)];
    if (brick < 0) return 0;
    const std::int32_t* corner = &closest[std::size_t(brick) * 512 + std::size_t(((i & 7) * 8 + (j & 7)) * 8 + (k & 7))];
    for (int c = 0; c < 8; ++c) add(corner[(c >> 2 & 1) * 64 + (c >> 1 & 1) * 8 + (c & 1)]);
    return count;
  }
  for (int c = 0; c < 8; ++c) {
    float v;
    std::int32_t t;
    voxel_at(i + (c >> 2 & 1), j + (c >> 1 & 1), k + (c & 1), v, t);
    add(t);
  }
  return count;
}

int WallField::candidates(const Vec3& p, int reach, std::int32_t* out, int capacity) const {
  if (reach == 0) return cell_candidates(cell_of(p), out);
  // Grid nodes: the 3x3x3 voxels around the voxel nearest to p.
  const Vec3 base = (p / voxel).array().round();
  const int i = int(base.x()), j = int(base.y()), k = int(base.z());
  int count = 0;
  for (int di = -1; di <= 1; ++di)
    for (int dj = -1; dj <= 1; ++dj)
      for (int dk = -1; dk <= 1; ++dk) {
        float v;
        std::int32_t t;
        voxel_at(i + di, j + dj, k + dk, v, t);
        if (t >= 0 && count < capacity && std::find(out, out + count, t) == out + count) out[count++] = t;
      }
  return count;
}

int WallField::local_minima(const Vec3& p, double range, SurfacePoint* out, int capacity) const {
  std::int32_t seeds[8];
  std::int32_t count = cell_candidates(cell_of(p), seeds);
  return local_minima_tracked(p, range, seeds, count, out, capacity);
}

int WallField::descend_all(const Vec3& p, const std::int32_t* triangles_near, int count, SurfacePoint* out) const {
  for (int c = 0; c < count; ++c) out[c] = descend(p, triangles_near[c]);
  return count;
}

// The descents from the candidates of p's cell end at local minima of the distance. Where they
// disagree in sign, one of them lies on a part of the surface that p sees from behind while
// another surface is closer: the cell's candidates may then have missed the closest triangle
// (on a feature thinner than a voxel, say), so the 3x3x3 voxels around p are asked too. The
// nearest minimum found decides the sign, and minima of the other sign are dropped: a point is
// inside or outside, never both.
//
// A point they put inside the solid is also held against the grid's trilinear sign. Beside a
// sheet thinner than a voxel (two faces back to back, microns apart), every candidate may lead to
// the face the point lies behind while the face in front of it is nearer by microns: measured on
// the blind flange die of ../shared (0.1461 mm behind one face, 0.1460 mm in front of the true
// closest one, whose triangle no voxel within a cell's reach names). The 27 voxels are asked
// then; should the minima still say inside where the grid says outside by more than half a voxel
// (beyond the grid's error, under 0.42 voxel on the shared dies: `diefill sdf --verify`), the
// grid's sign wins and the minima are turned round. Grains sit outside the walls, so this costs a
// grid read only where a contact overlaps deeply.
int WallField::consistent_minima(const Vec3& p, SurfacePoint* found, int n, bool* widened) const {
  const auto nearest = [&] {
    int best = 0;
    for (int c = 1; c < n; ++c)
      if (std::abs(found[c].distance) < std::abs(found[best].distance)) best = c;
    return best;
  };
  const auto mixed = [&] {
    for (int c = 1; c < n; ++c)
      if ((found[c].distance < 0) != (found[0].distance < 0)) return true;
    return false;
  };
  const bool looks_inside = n > 0 && found[nearest()].distance < 0;
  const double grid = looks_inside ? trilinear(p) : 0.0;
  const bool widen = mixed() || grid > 0;
  if (widened) *widened = widen;
  if (widen) {
    std::int32_t wider[27];
    n = descend_all(p, wider, candidates(p, 1, wider, 27), found);
  }
  bool inside = n > 0 && found[nearest()].distance < 0;
  if (inside && grid > 0.5 * voxel) {
    for (int c = 0; c < n; ++c) found[c].distance = -found[c].distance, found[c].normal = -found[c].normal;
    inside = false;
  }
  int kept = 0;
  for (int c = 0; c < n; ++c)
    if ((found[c].distance < 0) == inside) found[kept++] = found[c];
  return kept;
}

int WallField::merged_minima(SurfacePoint* minima, int n, double range, SurfacePoint* out, int capacity) {
  // Minima with nearly parallel normals lie on one smooth surface: a tessellated curve seen
  // from its concave side has a minimum on each facet near a facet edge, and counting both
  // would double the force there. Only the deepest of them is a contact; minima whose normals
  // differ by more than `smooth_angle` (a concave corner) are contacts each. Taken in the order
  // of their features, so that the same minima give the same contacts whichever walks found them.
  std::sort(minima, minima + n, [](const SurfacePoint& a, const SurfacePoint& b) { return a.feature < b.feature; });
  int found = 0;
  for (int c = 0; c < n; ++c) {
    const SurfacePoint& s = minima[c];
    if (s.distance > range) continue;
    int merged = -1;
    for (int f = 0; f < found && merged < 0; ++f)
      if (out[f].feature == s.feature || out[f].normal.dot(s.normal) > same_surface) merged = f;
    if (merged >= 0) {
      if (s.distance < out[merged].distance) out[merged] = s;
    } else if (found < capacity) {
      out[found++] = s;
    }
  }
  return found;
}

int WallField::local_minima_tracked(const Vec3& p, double range, std::int32_t* seeds, std::int32_t& count,
                                    SurfacePoint* out, int capacity) const {
  // A seed is a triangle to walk from, or (stored as ~t) an anchor: the last triangle of a smooth
  // surface that an earlier walk left over a sharp edge. A walk from an anchor that would cross
  // that edge again stops there and finds nothing (its minimum beyond is a seed of its own); one
  // that stays on the surface has found a minimum that appeared there as the point moved.
  SurfacePoint minima[27];
  std::int32_t next[16];
  int n = 0, next_count = 0;
  const auto track = [&](std::int32_t seed) {
    if (std::find(next, next + next_count, seed) == next + next_count) next[next_count++] = seed;
  };
  for (int c = 0; c < count; ++c) {
    const bool watching = seeds[c] < 0;
    int anchor = -1;
    const SurfacePoint minimum = descend(p, watching ? ~seeds[c] : seeds[c], &anchor, watching);
    if (anchor >= 0) track(~anchor);
    if (anchor >= 0 && watching) continue;
    minima[n++] = minimum;
    track(minimum.triangle);
  }
  bool widened = false;
  n = consistent_minima(p, minima, n, &widened);
  // Seeds move on unless the walks disagreed in sign (the wider voxels decided then) or there are
  // more than fit: the same seeds are walked again next time.
  if (!widened && next_count <= 8) {
    std::copy(next, next + next_count, seeds);
    count = next_count;
  }
  return merged_minima(minima, n, range, out, capacity);
}

bool WallField::nearest(const Vec3& p, int reach, SurfacePoint& out) const {
  std::int32_t triangles_near[27];
  const int count = candidates(p, reach, triangles_near, 27);
  SurfacePoint minima[27];
  const int n = consistent_minima(p, minima, descend_all(p, triangles_near, count, minima), nullptr);
  for (int c = 0; c < n; ++c)
    if (c == 0 || std::abs(minima[c].distance) < std::abs(out.distance)) out = minima[c];
  return n > 0;
}

double WallField::signed_distance(const Vec3& p) const {
  SurfacePoint best;
  return nearest(p, 0, best) ? best.distance : trilinear(p);
}

}  // namespace geometry
