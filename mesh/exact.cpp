// The only translation unit that includes Embree.
#include "mesh/exact.hpp"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include "mesh/geometry.hpp"
#include "mesh/versions.hpp"

namespace mesh {

struct ExactSurface::Impl {
  geometry::TriMesh mesh;  // double precision copy: distances are computed from it, not from floats
  geometry::Vec3 centre;   // Embree's float buffers hold coordinates relative to it
  bool inside_out = false;
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;

  struct Query {
    const Impl* self;
    geometry::Vec3 point;
    geometry::Vec3 closest;
    double distance;
  };

  static bool closest_callback(RTCPointQueryFunctionArguments* args) {
    auto* q = static_cast<Query*>(args->userPtr);
    const geometry::TriMesh& m = q->self->mesh;
    const geometry::Triangle& t = m.triangles[args->primID];
    const geometry::Vec3 c = closest_point_on_triangle(q->point, m.vertices[t[0]], m.vertices[t[1]],
                                                       m.vertices[t[2]]);
    const double d = (c - q->point).norm();
    if (d < q->distance) {
      q->distance = d;
      q->closest = c;
      // Slightly larger than d: Embree's float bounds must not cull the true closest triangle.
      args->query->radius = float(d * (1.0 + 1e-5) + 1e-12);
      return true;
    }
    return false;
  }

  // Faces the ray from `origin` crosses (parity is all a closed mesh needs).
  int crossings(const geometry::Vec3& origin, const geometry::Vec3& direction) const {
    int count = 0;
    float tnear = 0.0f;
    for (int guard = 0; guard < 100000; ++guard) {
      RTCRayHit rh = ray_from(origin, direction, tnear);
      RTCIntersectContext context;
      rtcInitIntersectContext(&context);
      rtcIntersect1(scene, &context, &rh);
      if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) break;
      ++count;
      tnear = std::nextafter(rh.ray.tfar, std::numeric_limits<float>::infinity()) +
              1e-7f * std::max(1.0f, rh.ray.tfar);
    }
    return count;
  }

  RTCRayHit ray_from(const geometry::Vec3& origin, const geometry::Vec3& direction, float tnear) const {
    const geometry::Vec3 o = origin - centre;
    RTCRayHit rh{};
    rh.ray.org_x = float(o.x());
    rh.ray.org_y = float(o.y());
    rh.ray.org_z = float(o.z());
    rh.ray.dir_x = float(direction.x());
    rh.ray.dir_y = float(direction.y());
    rh.ray.dir_z = float(direction.z());
    rh.ray.tnear = tnear;
    rh.ray.tfar = std::numeric_limits<float>::infinity();
    rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    return rh;
  }

  // Every face along a ray, coincident ones included: a filter that records each hit and rejects
  // it, so that traversal goes on (Embree's idiom for all hits). Stepping past the nearest hit
  // instead skipped a face lying where another one already was, as overlapping shells do.
  struct AllHits {
    RTCIntersectContext context;  // first: Embree passes the filter a pointer to it
    std::vector<unsigned> faces;
    bool grazes_an_edge = false;
  };

  static void record_hit(const RTCFilterFunctionNArguments* args) {
    auto* hits = reinterpret_cast<AllHits*>(args->context);
    const float u = RTCHitN_u(args->hit, args->N, 0), v = RTCHitN_v(args->hit, args->N, 0);
    // Within 1e-5 of an edge in float coordinates a crossing may be reported by both faces
    // beside it or by neither.
    constexpr float edge = 1e-5f;
    if (u < edge || v < edge || 1.0f - u - v < edge) hits->grazes_an_edge = true;
    hits->faces.push_back(RTCHitN_primID(args->hit, args->N, 0));
    args->valid[0] = 0;
  }

  // The faces the ray leaves through (along their outward normal) minus those it enters
  // through, counting every face once (spatial splits may report one twice); nullopt when the ray
  // passes within float rounding of an edge, where that count is not to be trusted.
  std::optional<int> winding_along(const geometry::Vec3& origin, const geometry::Vec3& direction) const {
    AllHits hits;
    rtcInitIntersectContext(&hits.context);
    hits.context.filter = &record_hit;
    RTCRayHit rh = ray_from(origin, direction, 0.0f);
    rtcIntersect1(scene, &hits.context, &rh);
    if (hits.grazes_an_edge) return std::nullopt;
    std::sort(hits.faces.begin(), hits.faces.end());
    hits.faces.erase(std::unique(hits.faces.begin(), hits.faces.end()), hits.faces.end());
    int winding = 0;
    for (const unsigned f : hits.faces) {
      const geometry::Triangle& t = mesh.triangles[f];
      const geometry::Vec3 outward = (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
      winding += outward.dot(direction) > 0 ? 1 : -1;
    }
    return winding;
  }
};

ExactSurface::ExactSurface(const geometry::TriMesh& mesh) : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.mesh = mesh;
  s.inside_out = geometry::signed_volume(mesh) < 0;
  const geometry::Box box = geometry::bounding_box(mesh);
  s.centre = box.empty() ? geometry::Vec3::Zero() : geometry::Vec3((box.lo + box.hi) / 2);
  // No thread count: Embree with TBB holds a static tbb::global_control at the count it is given
  // (RenderKit/embree issue 507), and "threads=1" left every later TBB loop of the process (the
  // winding-number band, OpenVDB's SDF build) on one core.
  s.device = rtcNewDevice(nullptr);
  s.scene = rtcNewScene(s.device);
  rtcSetSceneBuildQuality(s.scene, RTC_BUILD_QUALITY_HIGH);
  rtcSetSceneFlags(s.scene, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);  // for Impl::winding_along
  RTCGeometry geometry = rtcNewGeometry(s.device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.vertices.size()));
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    for (int d = 0; d < 3; ++d) vertices[3 * i + d] = float(mesh.vertices[i][d] - s.centre[d]);
  auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), mesh.triangles.size()));
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
    for (int d = 0; d < 3; ++d) indices[3 * i + d] = unsigned(mesh.triangles[i][d]);
  rtcSetGeometryPointQueryFunction(geometry, &Impl::closest_callback);
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(s.scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(s.scene);
}

ExactSurface::~ExactSurface() {
  if (impl_) {
    rtcReleaseScene(impl_->scene);
    rtcReleaseDevice(impl_->device);
  }
}

geometry::Vec3 ExactSurface::closest_point(const geometry::Vec3& p) const {
  Impl::Query q{impl_.get(), p, p, std::numeric_limits<double>::infinity()};
  RTCPointQuery query{};
  const geometry::Vec3 local = p - impl_->centre;
  query.x = float(local.x());
  query.y = float(local.y());
  query.z = float(local.z());
  query.radius = std::numeric_limits<float>::infinity();
  query.time = 0.0f;
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  rtcPointQuery(impl_->scene, &query, &context, nullptr, &q);
  return q.closest;
}

double ExactSurface::distance(const geometry::Vec3& p) const { return (closest_point(p) - p).norm(); }

bool ExactSurface::inside(const geometry::Vec3& p) const {
  // Skew directions, so that no ray runs along a face or through a vertex of axis-aligned meshes.
  static const geometry::Vec3 directions[3] = {geometry::Vec3(0.5377, 0.8322, 0.1353).normalized(),
                                               geometry::Vec3(-0.7071, 0.1534, -0.6902).normalized(),
                                               geometry::Vec3(0.2213, -0.6547, 0.7229).normalized()};
  int votes = 0;
  for (const geometry::Vec3& d : directions) votes += impl_->crossings(p, d) % 2;
  return (votes >= 2) != impl_->inside_out;
}

bool ExactSurface::inside_by_ray_majority(const geometry::Vec3& p, int rays) const {
  std::mt19937_64 random(7);
  std::normal_distribution<double> normal;
  int votes = 0;
  for (int r = 0, draws = 0; r < rays; ++draws) {
    const geometry::Vec3 direction = geometry::Vec3(normal(random), normal(random), normal(random)).normalized();
    const std::optional<int> winding = impl_->winding_along(p, direction);
    // A ray along an edge is drawn again; after 100 such draws the point lies on the surface
    // itself, where neither answer is wrong.
    if (!winding && draws < 100) continue;
    votes += winding.value_or(0) > 0;
    ++r;
  }
  return 2 * votes > rays;
}

}  // namespace mesh

namespace mesh {
std::string embree_version() { return RTC_VERSION_STRING; }
}  // namespace mesh
