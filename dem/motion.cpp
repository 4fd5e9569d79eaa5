#include "dem/motion.hpp"

#include <algorithm>

namespace dem {

Vec3 Motion::position(double t) const {
  Vec3 x = start_position, v = start_velocity;
  double t0 = 0;
  for (const Segment& s : segments) {
    const double dt = std::min(s.duration, std::max(0.0, t - t0));
    x += v * dt + 0.5 * s.acceleration * dt * dt;
    v += s.acceleration * dt;
    t0 += s.duration;
    if (t <= t0) return x;
  }
  return x + v * std::max(0.0, t - t0);
}

Vec3 Motion::velocity(double t) const {
  Vec3 v = start_velocity;
  double t0 = 0;
  for (const Segment& s : segments) {
    v += s.acceleration * std::min(s.duration, std::max(0.0, t - t0));
    t0 += s.duration;
    if (t <= t0) break;
  }
  return v;
}

Quat Motion::orientation(double t) const {
  const double angle = angular_velocity.norm() * t;
  if (angle == 0) return Quat::Identity();
  return Quat(Eigen::AngleAxisd(angle, angular_velocity.normalized()));
}

// The wall frame rotates about `pivot` (a point of the wall frame) and translates with
// position(t): world = position(t) + pivot + R(t) (local - pivot).
Vec3 Motion::to_world(double t, const Vec3& local) const {
  return position(t) + pivot + orientation(t) * (local - pivot);
}

Vec3 Motion::to_local(double t, const Vec3& world) const {
  return pivot + orientation(t).conjugate() * (world - position(t) - pivot);
}

Vec3 Motion::point_velocity(double t, const Vec3& p) const {
  return velocity(t) + angular_velocity.cross(p - position(t) - pivot);
}

bool Motion::moves() const {
  if (start_velocity.squaredNorm() > 0 || angular_velocity.squaredNorm() > 0) return true;
  for (const Segment& s : segments)
    if (s.acceleration.squaredNorm() > 0) return true;
  return false;
}

double Motion::top_speed() const {
  double top = start_velocity.norm(), t = 0;
  for (const Segment& s : segments) top = std::max(top, velocity(t += s.duration).norm());
  return top;
}

}  // namespace dem
