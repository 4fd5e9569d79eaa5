// The winding-number solid (mesh/winding_solid.hpp): OpenVDB's unsigned distance of the soup,
// signed by the generalized winding number, meshed at its zero surface.
#include "mesh/winding_solid.hpp"

#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <openvdb/tree/LeafManager.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <optional>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <tuple>
#include <utility>
#include <unordered_map>

#include "core/log.hpp"
#include "geometry/winding.hpp"
#include "mesh/cgal_ops.hpp"
#include "mesh/exact.hpp"
#include "mesh/openvdb_adapter.hpp"

namespace mesh::detail {

namespace {

// Cells of the distance band on each side of the surface. Where the region's surface crosses a
// gap (a crack, a missing face) farther than the band from any triangle, no active voxel sees it
// and OpenVDB leaves a hole in its mesh: the band is then doubled, up to the widest.
constexpr float band_cells = 3.0f;
constexpr float widest_band_cells = 24.0f;
// OpenVDB's adaptivity for a first, coarser zero surface: on the open gear of the shared dies
// (cells of 0.0625 mm) 0.05 kept the surface within 0.060 mm with 129 k triangles instead of
// 1.6 M; 0.15 moved it 0.096 mm.
constexpr double flat_adaptivity = 0.05;

bool ambiguous(double w) { return w > 0.25 && w < 0.75; }

geometry::TriMesh to_trimesh(const std::vector<openvdb::Vec3s>& points, const std::vector<openvdb::Vec3I>& triangles,
                             const std::vector<openvdb::Vec4I>& quads) {
  geometry::TriMesh out;
  out.vertices.reserve(points.size());
  for (const openvdb::Vec3s& p : points) out.vertices.emplace_back(p.x(), p.y(), p.z());
  for (const openvdb::Vec3I& t : triangles) out.triangles.push_back({int(t[0]), int(t[1]), int(t[2])});
  for (const openvdb::Vec4I& q : quads) {
    out.triangles.push_back({int(q[0]), int(q[1]), int(q[2])});
    out.triangles.push_back({int(q[0]), int(q[2]), int(q[3])});
  }
  // OpenVDB winds its polygons for a level set negative inside; the mesh module's are
  // counter-clockwise from outside.
  if (geometry::signed_volume(out) < 0)
    for (geometry::Triangle& t : out.triangles) std::swap(t[1], t[2]);
  return out;
}

// Terms the winding number would sum to sign every active voxel of `grid`: the mean over about
// 2000 voxels spread evenly over the band, times its voxel count.
double signing_terms(const openvdb::FloatGrid& grid, const geometry::WindingNumber& winding) {
  const openvdb::Index64 voxels = grid.activeVoxelCount();
  const openvdb::Index64 stride = std::max<openvdb::Index64>(1, voxels / 2000);
  std::size_t terms = 0, samples = 0;
  openvdb::Index64 index = 0;
  for (auto voxel = grid.cbeginValueOn(); voxel; ++voxel, ++index)
    if (index % stride == 0) {
      const openvdb::Vec3d p = grid.transform().indexToWorld(voxel.getCoord());
      terms += winding.terms(geometry::Vec3(p.x(), p.y(), p.z()));
      ++samples;
    }
  return samples == 0 ? 0.0 : double(terms) / double(samples) * double(voxels);
}

// The soup's unsigned distance within `band` cells, negated where the winding number is ≥ ½;
// nothing where signing it would sum more than `max_terms` terms, whose estimate `terms` holds.
openvdb::FloatGrid::Ptr signed_band(const geometry::TriMesh& soup, const geometry::WindingNumber& winding, double cell_m, float band,
                                    double max_terms, double& terms) {
  // The samples are offset from the axes' origin by 1/π of a cell: CAD faces lie on round
  // coordinates, and samples exactly on a face (distance 0, neither side) left OpenVDB's zero
  // surface with sheets of no thickness. Unshifted, the flanged ring's solid at cells of 0.2 mm
  // had 17 shells, 6,685 degenerate faces and 12,440 crossing triangle pairs; shifted, its zero
  // surface crosses nowhere and the solid is one shell.
  auto transform = openvdb::math::Transform::createLinearTransform(cell_m);
  const geometry::Vec3 origin = geometry::Vec3::Constant(0.318309886 * cell_m);
  transform->postTranslate(openvdb::Vec3d(origin.x(), origin.y(), origin.z()));
  const TriMeshAdapter adapter{soup, 1.0 / cell_m, origin};
  openvdb::FloatGrid::Ptr grid = openvdb::tools::meshToVolume<openvdb::FloatGrid>(
      adapter, *transform, band, band, openvdb::tools::UNSIGNED_DISTANCE_FIELD);
  terms = signing_terms(*grid, winding);
  if (terms > max_terms) return nullptr;
  openvdb::tree::LeafManager<openvdb::FloatTree> leaves(grid->tree());
  tbb::parallel_for(leaves.leafRange(), [&](const openvdb::tree::LeafManager<openvdb::FloatTree>::LeafRange& range) {
    for (auto leaf = range.begin(); leaf; ++leaf)
      for (auto voxel = leaf->beginValueOn(); voxel; ++voxel) {
        const openvdb::Vec3d p = transform->indexToWorld(voxel.getCoord());
        if (winding(geometry::Vec3(p.x(), p.y(), p.z())) >= 0.5) voxel.setValue(-voxel.getValue());
      }
  });
  // Beyond the band the sign follows the band's: inside stays inside.
  openvdb::tools::signedFloodFill(grid->tree());
  return grid;
}

// The zero surface of a signed band; `adaptivity` (OpenVDB's, 0 to 1) merges the cells of flat
// regions, except where `fine` (if given) has active voxels.
geometry::TriMesh zero_surface(const openvdb::FloatGrid& grid, double adaptivity, const openvdb::BoolTree::Ptr& fine = nullptr) {
  openvdb::tools::VolumeToMesh mesher(0.0, adaptivity);
  if (fine) mesher.setAdaptivityMask(fine);
  mesher(grid);
  std::vector<openvdb::Vec3s> points(mesher.pointList().get(), mesher.pointList().get() + mesher.pointListSize());
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  for (std::size_t n = 0; n < mesher.polygonPoolListSize(); ++n) {
    const openvdb::tools::PolygonPool& pool = mesher.polygonPoolList()[n];
    for (std::size_t k = 0; k < pool.numQuads(); ++k) quads.push_back(pool.quad(k));
    for (std::size_t k = 0; k < pool.numTriangles(); ++k) triangles.push_back(pool.triangle(k));
  }
  return to_trimesh(points, triangles, quads);
}

// Marks the voxels within `reach` of each point, where merged cells must not reach.
void mark_fine(openvdb::BoolTree& fine, const std::vector<geometry::Vec3>& points, const openvdb::math::Transform& transform) {
  constexpr int reach = 2;  // [voxels]
  for (const geometry::Vec3& p : points) {
    const openvdb::Coord c = transform.worldToIndexCellCentered(openvdb::Vec3d(p.x(), p.y(), p.z()));
    fine.fill(openvdb::CoordBBox(c.offsetBy(-reach), c.offsetBy(reach)), true, true);
  }
}

bool has_boundary(const geometry::TriMesh& mesh) {
  std::unordered_map<std::uint64_t, int> uses;
  uses.reserve(3 * mesh.triangles.size());
  for (const geometry::Triangle& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t a = std::uint32_t(t[k]), b = std::uint32_t(t[(k + 1) % 3]);
      ++uses[a < b ? (a << 32) | b : (b << 32) | a];
    }
  return std::any_of(uses.begin(), uses.end(), [](const auto& use) { return use.second == 1; });
}

// Where the input is thinner than a cell (the two sides of a slit) or comes to an edge between
// cells, moving the zero surface onto it folds it: triangles turned over through their
// neighbours, or flattened onto a line (the flanged ring at cells of 0.2 mm: 1,658 crossing
// pairs, none before the move). The corners of every such triangle go back where the zero
// surface had them, until none is left or only the zero surface's own are: returns the corners
// of those (OpenVDB's merged cells crossed in 3 pairs on the sprocket of the shared dies).
std::vector<geometry::Vec3> put_back_folds(geometry::TriMesh& mesh, const std::vector<geometry::Vec3>& unmoved) {
  for (;;) {
    const std::vector<bool> faulty = faulty_triangles(mesh);
    std::size_t put_back = 0;
    std::vector<geometry::Vec3> unmoved_faulty;
    for (std::size_t f = 0; f < faulty.size(); ++f) {
      if (!faulty[f]) continue;
      for (const int corner : mesh.triangles[f]) {
        geometry::Vec3& p = mesh.vertices[std::size_t(corner)];
        if (p == unmoved[std::size_t(corner)]) unmoved_faulty.push_back(p);
        else p = unmoved[std::size_t(corner)], ++put_back;
      }
    }
    if (put_back == 0) return unmoved_faulty;
  }
}

// Whether `outside`, a point `offset` off a face on the side of winding number < ½, lies in a
// sliver of outside between parts in contact: a segment through it of `contact_gap_m` at most,
// along one of 13 directions (the axes, the faces' and the cube's diagonals: one within 28° of
// any), has both ends in the solid. Each half of the segment is at most half of `offset`, so
// that the face the point stands off and a wall meeting it in a corner are never its two ends.
bool in_contact_sliver(const geometry::Vec3& outside, double offset, const geometry::WindingNumber& winding, const ExactSurface& surface) {
  const double reach = std::min(0.5 * contact_gap_m, 0.5 * offset);
  if (surface.distance(outside) > reach) return false;
  static const std::array<geometry::Vec3, 13> lines = [] {
    std::array<geometry::Vec3, 13> d;
    int n = 0;
    for (int x = -1; x <= 1; ++x)
      for (int y = -1; y <= 1; ++y)
        for (int z = -1; z <= 1; ++z) {
          const geometry::Vec3 v(x, y, z);
          // one of each pair ±v: the first nonzero coordinate positive
          if ((x > 0) || (x == 0 && y > 0) || (x == 0 && y == 0 && z > 0)) d[std::size_t(n++)] = v.normalized();
        }
    return d;
  }();
  return std::any_of(lines.begin(), lines.end(), [&](const geometry::Vec3& d) {
    return winding(outside + reach * d) >= 0.5 && winding(outside - reach * d) >= 0.5;
  });
}

// Input points the result covers though they bound the region, gathered from every core: the
// faces of closed gaps or of parts in contact, and the farthest of them inside the result.
struct CoveredFaces {
  std::mutex mutex;
  std::vector<geometry::Vec3> points;

  void add(const geometry::Vec3& p) {
    const std::lock_guard<std::mutex> lock(mutex);
    points.push_back(p);
  }
  // The farthest point from `result`'s surface and its distance, over points in a fixed order.
  std::pair<double, geometry::Vec3> farthest(const ExactSurface* result) {
    std::sort(points.begin(), points.end(),
              [](const geometry::Vec3& a, const geometry::Vec3& b) { return std::tie(a.x(), a.y(), a.z()) < std::tie(b.x(), b.y(), b.z()); });
    std::pair<double, geometry::Vec3> out{0.0, geometry::Vec3::Zero()};
    for (const geometry::Vec3& p : points) {
      const double depth = result->distance(p);
      if (depth > out.first) out = {depth, p};
    }
    return out;
  }
};

// A grain of radius `radius_m` against the input: whether it can touch a point of its bounding
// surface from the free space, which lies inside the solid or outside it.
struct GrainProbe {
  const geometry::WindingNumber& winding;
  const ExactSurface& surface;
  double radius_m;

  // `p` lies on a face of unit `normal`, with the solid on that side or not.
  bool touches(const geometry::Vec3& p, const geometry::Vec3& normal, bool solid_ahead, bool free_space_inside) const {
    const auto free_at = [&](const geometry::Vec3& x) { return (winding(x) >= 0.5) == free_space_inside; };
    const geometry::Vec3 centre = p + (solid_ahead == free_space_inside ? radius_m : -radius_m) * normal;
    if (!free_at(centre)) return false;
    const geometry::Vec3 nearest = surface.closest_point(centre);
    const double clearance = (nearest - centre).norm();
    if (clearance >= 0.999 * radius_m) return true;  // the grain fits
    // What it overlaps must bound the free space, not lie in the open: just beyond it (a
    // hundredth of the radius: the solid there may be a sliver) is not free space. A centre on
    // a face, as at a sample on an edge, overlaps that face.
    return clearance > 1e-3 * radius_m && free_at(nearest + 1e-2 * radius_m / clearance * (nearest - centre));
  }
};

// `zero` with its vertices moved onto the closest input point, and how far that leaves the
// input's bounding surface from it, not counting the faces of `gaps` it closed; `beyond` (if
// given) receives the input's sample points left farther than a cell from it.
WindingSolid on_input(geometry::TriMesh zero, const geometry::TriMesh& soup, const ExactSurface& surface, const geometry::WindingNumber& winding,
                      double cell_m, const ClosableGaps& gaps, std::vector<geometry::Vec3>* beyond = nullptr) {
  // The zero surface cuts corners by up to a cell; its vertices moved onto the closest input
  // point lie on the surface the file means, sharp edges and flat faces included (a flat top
  // face stays exactly flat, which the die's opening needs).
  // Where the file has no face within a cell (a face missing from it), the zero surface closes
  // the gap within a cell of where the face was, not on it; at the part's extremes that face was
  // flat (the flanged ring of the shared dies lacks its flange face, the side the die opens on),
  // so such vertices within a cell of the input's bounding box go onto the box's face.
  const geometry::Box box = geometry::bounding_box(soup);
  const std::vector<geometry::Vec3> unmoved = zero.vertices;
  tbb::parallel_for(std::size_t(0), zero.vertices.size(), [&](std::size_t v) {
    geometry::Vec3& p = zero.vertices[v];
    const geometry::Vec3 closest = surface.closest_point(p);
    if ((closest - p).norm() <= cell_m) {
      p = closest;
      return;
    }
    for (int axis = 0; axis < 3; ++axis)
      for (const double extreme : {box.lo[axis], box.hi[axis]})
        if (std::abs(p[axis] - extreme) <= cell_m) p[axis] = extreme;
  });
  WindingSolid out;
  out.folded_at = put_back_folds(zero, unmoved);
  // What bounds the region in the input: sample points whose two sides fall on either side
  // of ½ (a quarter cell off the face); faces buried inside or left in the open do not. Nor do
  // faces of parts in contact, across a sliver of outside (`in_contact_sliver`), nor those the
  // result covers where no grain of the closable diameter can touch them from the free space
  // (`gaps`): there the cells are too coarse to keep the free space open, and no grain could
  // tell (docs/MESHES.md, "Mesh repair").
  const double offset = 0.25 * cell_m;
  const GrainProbe grain{winding, surface, 0.5 * gaps.closable_m};
  // The samples are asked on every core (farthest_sample): the result's exact surface is built
  // once, by the first sample that needs it.
  std::unique_ptr<ExactSurface> result;
  std::once_flag result_built;
  const auto build_result = [&] { std::call_once(result_built, [&] { result = std::make_unique<ExactSurface>(zero); }); };
  CoveredFaces gap_faces, contact_faces;
  FarthestSample moved = farthest_sample(
      soup, zero,
      [&](const geometry::Vec3& p, const geometry::Vec3& normal) {
        const bool solid_ahead = winding(p + offset * normal) >= 0.5;
        if (solid_ahead == (winding(p - offset * normal) >= 0.5)) return false;
        if (in_contact_sliver(p + (solid_ahead ? -offset : offset) * normal, offset, winding, surface)) {
          build_result();
          contact_faces.add(p);
          return false;
        }
        if (grain.radius_m <= 0.0 || grain.touches(p, normal, solid_ahead, gaps.free_space_inside)) return true;
        build_result();
        if (result->inside(p) == gaps.free_space_inside) return true;  // the result keeps the free space
        gap_faces.add(p);
        return false;
      },
      beyond ? cell_m : std::numeric_limits<double>::infinity());
  std::tie(out.gap_closed_m, out.gap_closed_at) = gap_faces.farthest(result.get());
  std::tie(out.contact_joined_m, out.contact_joined_at) = contact_faces.farthest(result.get());
  out.moved_across_thin_solid = grain.radius_m > 0.0 && moved.distance_m > 0.0 &&
                                !grain.touches(moved.point, moved.normal,
                                               winding(moved.point + offset * moved.normal) >= 0.5, !gaps.free_space_inside);
  if (beyond) *beyond = std::move(moved.beyond);
  out.moved_m = moved.distance_m;
  out.moved_most_at = moved.point;
  out.mesh = std::move(zero);
  return out;
}

struct SurveyTally {
  long solid = 0, unclear = 0;
  geometry::Box unclear_box;
  void add(const SurveyTally& other) {
    solid += other.solid;
    unclear += other.unclear;
    if (!other.unclear_box.empty()) {
      unclear_box.extend(other.unclear_box.lo);
      unclear_box.extend(other.unclear_box.hi);
    }
  }
};

// The survey's cells, visited as an octree of blocks. The winding number is harmonic away from
// the surface: in a block no triangle reaches into it varies smoothly, so where it is clearly on
// one side (at most `clear_margin`, or at least 1 - `clear_margin`: an inside-out shell's -1
// and overlapping shells' 2 included) at the block's centre and eight corners, every cell of
// the block takes that side. The rest is split
// down to single cells, each read at its centre: only the cells near the surface, or around an
// open hole where the winding number drifts, are read one by one (one by one, the 96³ cells
// were two thirds of a small die's repair under the sanitizers).
class Survey {
 public:
  Survey(const geometry::TriMesh& soup, const geometry::Box& box, double cell_m, const Eigen::Vector3i& cells)
      : winding_(soup), surface_(soup), box_(box), cell_m_(cell_m), cells_(cells) {}

  SurveyTally block(const Eigen::Vector3i& first, int size) const {
    const Eigen::Vector3i end = (first.array() + size).min(cells_.array());
    SurveyTally tally;
    if (size <= 2) {  // a block's nine samples would cost more than its cells
      for (int k = first.z(); k < end.z(); ++k)
        for (int j = first.y(); j < end.y(); ++j)
          for (int i = first.x(); i < end.x(); ++i) {
            const Eigen::Vector3i cell(i, j, k);
            add_cells(winding_(corner(cell) + geometry::Vec3::Constant(0.5 * cell_m_)), cell, cell + Eigen::Vector3i::Ones(), tally);
          }
      return tally;
    }
    const geometry::Vec3 lo = corner(first), hi = corner(end), centre = 0.5 * (lo + hi);
    if (surface_.distance(centre) > 0.5 * (hi - lo).norm()) {
      if (const std::optional<double> w = clear_value(lo, hi, centre)) {
        add_cells(*w, first, end, tally);
        return tally;
      }
    }
    const int half = size / 2;
    for (int octant = 0; octant < 8; ++octant) {
      const Eigen::Vector3i child = first + half * Eigen::Vector3i(octant & 1, (octant >> 1) & 1, (octant >> 2) & 1);
      if ((child.array() < cells_.array()).all()) tally.add(block(child, half));
    }
    return tally;
  }

 private:
  static constexpr double clear_margin = 0.15;

  geometry::Vec3 corner(const Eigen::Vector3i& cell) const { return box_.lo + cell_m_ * cell.cast<double>(); }

  // The winding number at the block's centre where it and the eight corners' are all at most
  // `clear_margin` or all at least 1 - `clear_margin`; nothing otherwise.
  std::optional<double> clear_value(const geometry::Vec3& lo, const geometry::Vec3& hi, const geometry::Vec3& centre) const {
    const double w = winding_(centre);
    const bool solid = w >= 0.5;
    const auto clear = [&](double x) { return solid ? x >= 1.0 - clear_margin : x <= clear_margin; };
    if (!clear(w)) return std::nullopt;
    for (int k = 0; k < 8; ++k) {
      const geometry::Vec3 p((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(), (k & 4) ? hi.z() : lo.z());
      if (!clear(winding_(p))) return std::nullopt;
    }
    return w;
  }

  void add_cells(double w, const Eigen::Vector3i& first, const Eigen::Vector3i& end, SurveyTally& tally) const {
    const long count = long(end.x() - first.x()) * (end.y() - first.y()) * (end.z() - first.z());
    if (w >= 0.5) tally.solid += count;
    if (ambiguous(w)) {
      tally.unclear += count;
      tally.unclear_box.extend(corner(first));
      tally.unclear_box.extend(corner(end));
    }
  }

  geometry::WindingNumber winding_;
  ExactSurface surface_;
  geometry::Box box_;
  double cell_m_;
  Eigen::Vector3i cells_;
};

// Cells along a top-level block's side: a power of two.
constexpr int survey_block_cells = 16;

// The zero surface with flat regions' cells merged (ten times fewer triangles on the open gear
// of the shared dies), and fine cells wherever merging left the input's surface more than a cell
// away: the sprocket's open visual mesh at cells of 1 mm, meshed fine everywhere, was 2.3 million
// triangles, most of its repair's and its field's cost; fine cells also where merged ones cross
// each other. Nothing where the merged surface is empty, open, or still moved beyond a cell or
// crossing once fine cells stop helping (the planetary gear set as a cavity: die walls between
// its gears thinner than a cell, which no cell size here keeps).
std::optional<WindingSolid> merged_where_flat(const openvdb::FloatGrid& grid, const geometry::TriMesh& soup,
                                              const ExactSurface& surface, const geometry::WindingNumber& winding, double cell_m,
                                              const ClosableGaps& gaps) {
  constexpr int most_rounds = 3;
  const auto fine = std::make_shared<openvdb::BoolTree>(false);
  std::vector<geometry::Vec3> beyond;
  double moved_before = std::numeric_limits<double>::infinity();
  std::size_t folded_before = std::numeric_limits<std::size_t>::max();
  for (int round = 0; round <= most_rounds; ++round) {
    geometry::TriMesh zero = zero_surface(grid, flat_adaptivity, round == 0 ? nullptr : fine);
    if (zero.triangles.empty() || has_boundary(zero)) return std::nullopt;
    WindingSolid solid = on_input(std::move(zero), soup, surface, winding, cell_m, gaps, &beyond);
    diefill::log::debug("repair: winding-number solid, merged where flat (round {}): {} triangles, moved {:.4g} mm at "
                        "({:.4g}, {:.4g}, {:.4g}) mm, {} input samples beyond a cell, {} corners of crossing triangles",
                        round, solid.mesh.triangles.size(), solid.moved_m * 1e3, solid.moved_most_at.x() * 1e3,
                        solid.moved_most_at.y() * 1e3, solid.moved_most_at.z() * 1e3, beyond.size(),
                        solid.folded_at.size());
    if (solid.moved_m <= cell_m && solid.folded_at.empty()) return solid;
    if (solid.moved_m >= moved_before && solid.folded_at.size() >= folded_before) return std::nullopt;
    moved_before = solid.moved_m, folded_before = solid.folded_at.size();
    mark_fine(*fine, beyond, grid.transform());
    mark_fine(*fine, solid.folded_at, grid.transform());
  }
  return std::nullopt;
}

}  // namespace

WindingSurvey survey_winding(const geometry::TriMesh& soup, int cells) {
  const geometry::Box box = geometry::bounding_box(soup);
  const double h = box.size().maxCoeff() / cells;
  const Eigen::Vector3i n = (box.size() / h).array().ceil().cast<int>().max(1);
  const Survey survey(soup, box, h, n);
  const Eigen::Vector3i blocks = (n.array() + survey_block_cells - 1) / survey_block_cells;
  const SurveyTally total = tbb::parallel_reduce(
      tbb::blocked_range<int>(0, blocks.prod()), SurveyTally{},
      [&](const tbb::blocked_range<int>& range, SurveyTally tally) {
        for (int b = range.begin(); b < range.end(); ++b) {
          const Eigen::Vector3i index(b % blocks.x(), (b / blocks.x()) % blocks.y(), b / (blocks.x() * blocks.y()));
          tally.add(survey.block(survey_block_cells * index, survey_block_cells));
        }
        return tally;
      },
      [](SurveyTally a, const SurveyTally& b) {
        a.add(b);
        return a;
      });
  WindingSurvey out;
  const double cell_volume = h * h * h;
  out.solid_volume_m3 = double(total.solid) * cell_volume;
  out.solid_cells = total.solid;
  out.ambiguous_volume_m3 = double(total.unclear) * cell_volume;
  out.ambiguous_box = total.unclear_box;
  return out;
}

double winding_solid_cells(double surface_area_m2, double cell_m) {
  return 2.0 * double(band_cells) * surface_area_m2 / (cell_m * cell_m);
}

WindingSolid winding_solid(const geometry::TriMesh& soup, double cell_m, const ClosableGaps& gaps, double max_terms) {
  initialise_openvdb();
  const geometry::WindingNumber winding(soup);
  const ExactSurface surface(soup);
  double spent = 0.0;
  for (float band = band_cells; band <= widest_band_cells; band *= 2) {
    double terms = 0.0;
    const openvdb::FloatGrid::Ptr grid = signed_band(soup, winding, cell_m, band, max_terms - spent, terms);
    if (!grid) {
      WindingSolid refused;
      refused.refused_terms = spent + terms;
      return refused;
    }
    spent += terms;
    if (std::optional<WindingSolid> solid = merged_where_flat(*grid, soup, surface, winding, cell_m, gaps)) return *solid;
    // Every cell fine.
    geometry::TriMesh zero = zero_surface(*grid, 0.0);
    if (zero.triangles.empty()) return {};  // nothing has winding number ≥ ½
    if (!has_boundary(zero)) return on_input(std::move(zero), soup, surface, winding, cell_m, gaps);
  }
  return {};  // not closed within the widest band
}

}  // namespace mesh::detail
