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
  inertia.push_back(0.4 * m * r * r);
  material.push_back(material_index);
  active.push_back(1);
  body.push_back(-1);
  wall_slots.resize(wall_slots.size() + wall_slots_per_particle);
}

}  // namespace dem
