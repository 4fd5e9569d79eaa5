#include "dem/contact.hpp"

#include <algorithm>

namespace dem {

namespace {

// One dimensionless collision at unit approach speed: x'' = -max(0, f(x) + damping g(x) x'),
// with f = (4/3) x^{3/2}, g = sqrt(2) x^{1/4} for Hertz and f = x, g = 1 for the linear law
// (time in units of sqrt(m*/k), or of the Hertz equivalent; e depends on the damping only).
double collide(NormalLaw law, double damping) {
  auto accel = [&](double x, double v) {
    if (x <= 0) return 0.0;
    double f, g;
    if (law == NormalLaw::hertz) {
      f = (4.0 / 3.0) * x * std::sqrt(x);
      g = std::sqrt(2.0) * std::sqrt(std::sqrt(x));
    } else {
      f = x;
      g = 1.0;
    }
    return -std::max(0.0, f + damping * g * v);
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

double restitution_for_damping(NormalLaw law, double damping) { return collide(law, damping); }

double damping_for_restitution(NormalLaw law, double e) {
  if (e >= 1.0) return 0.0;
  double lo = 0.0, hi = 1.0;
  while (collide(law, hi) > e) hi *= 2.0;  // restitution falls with damping
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (collide(law, mid) > e ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace dem
