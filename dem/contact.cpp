#include "dem/contact.hpp"

#include <algorithm>

namespace dem {

namespace {

// The law's f and g (contact.hpp): f = (4/3) x^{3/2}, g = sqrt(2) x^{1/4} for Hertz, f = x, g = 1
// for the linear law; e depends on the damping only.
double collide(double (*unit_force)(double), double (*unit_damping)(double), double damping) {
  auto accel = [&](double x, double v) {
    if (x <= 0) return 0.0;
    return -std::max(0.0, unit_force(x) + damping * unit_damping(x) * v);
  };
  double x = 0.0, v = 1.0;
  const double dt = 2e-4;
  for (int step = 0; step < 1000000; ++step) {
    // Classical Runge-Kutta on (x, v).
    const double k1x = v, k1v = accel(x, v);
    const double k2x = v + 0.5 * dt * k1v, k2v = accel(x + 0.5 * dt * k1x, v + 0.5 * dt * k1v);
    const double k3x = v + 0.5 * dt * k2v, k3v = accel(x + 0.5 * dt * k2x, v + 0.5 * dt * k2v);
    const double k4x = v + dt * k3v, k4v = accel(x + dt * k3x, v + dt * k3v);
    const double x_next = x + dt / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
    const double v_next = v + dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    if (step > 0 && x_next <= 0) {
      // Interpolate the velocity at the crossing of x = 0.
      const double s = x / (x - x_next);
      return -(v + s * (v_next - v));
    }
    x = x_next;
    v = v_next;
  }
  return 0.0;
}

}  // namespace

double restitution_for_damping(double (*unit_force)(double), double (*unit_damping)(double), double damping) {
  return collide(unit_force, unit_damping, damping);
}

double damping_for_restitution(double (*unit_force)(double), double (*unit_damping)(double), double e) {
  if (e >= 1.0) return 0.0;
  double lo = 0.0, hi = 1.0;
  while (collide(unit_force, unit_damping, hi) > e) hi *= 2.0;  // restitution falls with damping
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (collide(unit_force, unit_damping, mid) > e ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace dem
