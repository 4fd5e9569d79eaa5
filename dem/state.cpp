#include "dem/state.hpp"

#include <numbers>

namespace dem {

void State::add_sphere(std::int64_t particle_id, const Vec3& position, double r, double density,
                       int material_index, const Vec3& velocity, const Vec3& angular_velocity) {
  const double m = density * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  id.push_back(particle_id);
  x.push_back(position);
  v.push_back(velocity);
  w.push_back(angular_velocity);
  f.push_back(Vec3::Zero());
  torque.push_back(Vec3::Zero());
  radius.push_back(r);
  mass.push_back(m);
  material.push_back(material_index);
  active.push_back(1);
  body.push_back(-1);
}

std::size_t State::memory_bytes() const {
  std::size_t total = 0;
  const auto add = [&total](const auto&... arrays) { ((total += arrays.capacity() * sizeof(arrays[0])), ...); };
  add(id, x, v, w, f, torque, radius, mass, material, active, body, wall_slots, scratch_wall_power, wall_candidates);
  add(bodies.x, bodies.v, bodies.q, bodies.l, bodies.f, bodies.torque, bodies.mass, bodies.inertia, bodies.volume,
      bodies.active, bodies.member_start, bodies.member, bodies.offset);
  const NeighbourList& nl = neighbours;
  add(nl.row_start, nl.partner, nl.tangential, nl.rolling, nl.touching, nl.cross_start, nl.cross_reverse_start,
      nl.cross_reverse, nl.near_wall, nl.x_at_build, nl.wall_shift_at_build);
  add(cross_forces.force, cross_forces.torque);
  return total;
}

}  // namespace dem
