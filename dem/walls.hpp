#pragma once
// Grain-wall contacts: analytic planes, and rigid mesh walls queried through their WallField
// (exact local minima of the distance: both faces of a concave corner, one contact at a convex
// edge) in the wall's own frame, moved by its prescribed motion. The wall's velocity at the
// contact point enters damping and friction; history is kept per grain and wall contact.
#include <array>

#include "dem/model.hpp"
#include "dem/state.hpp"

namespace dem {

// One grain-wall contact before the law is applied.
struct WallHit {
  std::int32_t wall;   // planes first, then mesh walls
  Vec3 normal;         // unit, from the wall towards the grain centre
  double distance;     // signed, centre to surface [m]
  Vec3 point;          // contact point on the surface [m]
  Vec3 wall_velocity;  // of the wall's material at the point [m/s]
  Vec3 wall_angular_velocity;
};

// Every wall contact of a grain at x with radius r (at most `capacity`). `cache`, when given,
// holds one WallCandidates per mesh wall for this grain.
int wall_hits(const Model& model, double time, const Vec3& x, double r, WallHit* out, int capacity,
              WallCandidates* cache = nullptr);

// At a neighbour rebuild: the grains within radius plus skin of a wall.
void collect_near_wall(const Model& model, State& state);

// Signed distance from x to the nearest wall [m] (negative inside a wall), for monitors.
double wall_distance(const Model& model, double time, const Vec3& x);

}  // namespace dem
