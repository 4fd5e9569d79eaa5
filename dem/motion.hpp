#pragma once
// Prescribed rigid motion of a wall: translation with piecewise constant acceleration (start,
// accelerate, cruise, decelerate, dwell, return, ...) and rotation at constant angular velocity
// about a pivot. Analytic in time, so that a step never accumulates error.
#include <vector>

#include "dem/types.hpp"

namespace dem {

struct Motion {
  struct Segment {
    double duration = 0;                 // [s]
    Vec3 acceleration = Vec3::Zero();    // [m/s²]
  };
  Vec3 start_position = Vec3::Zero();    // [m] at t = 0
  Vec3 start_velocity = Vec3::Zero();    // [m/s]
  std::vector<Segment> segments;         // after the last one the velocity stays constant
  Vec3 angular_velocity = Vec3::Zero();  // [rad/s]
  Vec3 pivot = Vec3::Zero();             // [m] in the wall frame

  Vec3 position(double t) const;          // of the wall frame's origin [m]
  Vec3 velocity(double t) const;          // [m/s]
  Quat orientation(double t) const;
  // Velocity of the wall's material point at world position p.
  Vec3 point_velocity(double t, const Vec3& p) const;
  // World from wall frame and back.
  Vec3 to_world(double t, const Vec3& local) const;
  Vec3 to_local(double t, const Vec3& world) const;
  bool moves() const;
  // Largest translation speed over the whole motion [m/s] (the velocity is piecewise linear in
  // time, so its norm peaks where a segment starts or ends).
  double top_speed() const;
};

}  // namespace dem
