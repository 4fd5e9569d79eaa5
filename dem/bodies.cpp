#include "dem/bodies.hpp"

#include <cmath>

#include "core/error.hpp"

namespace dem {

namespace {

// Members follow the body: x = X + R p, v = V + ω × (x − X), spin ω.
void follow_body(State& s, std::size_t b, bool positions) {
  Bodies& B = s.bodies;
  const Vec3 w = B.angular_velocity(b);
  for (std::int32_t k = B.member_start[b]; k < B.member_start[b + 1]; ++k) {
    const std::size_t i = std::size_t(B.member[std::size_t(k)]);
    if (positions) s.x[i] = B.x[b] + B.q[b] * B.offset[std::size_t(k)];
    s.v[i] = B.v[b] + w.cross(s.x[i] - B.x[b]);
    s.w[i] = w;
  }
}

// The flow of ½π_k²/I_k over t turns the body about its axis k by θ = t π_k / I_k, and its
// body-frame momentum π the other way. The turn is by the Cayley angle 2 atan(θ/2) instead: the
// exact flow of another function of π_k (so still a Poisson map keeping |π|, odd in t, and the
// composition still symplectic, time-reversible and second order), for one division where a
// sine and a cosine took a fifth of a body's step. q is left unnormalised: the caller
// normalises once.
void rotate_about_axis(int k, double t, const Vec3& inertia, Vec3& pi, Quat& q) {
  const double tau = 0.5 * t * pi[k] / inertia[k];
  const double d = 1 / (1 + tau * tau);
  const double c = (1 - tau * tau) * d, sn = 2 * tau * d;
  const int a = (k + 1) % 3, b = (k + 2) % 3;
  const double pa = pi[a], pb = pi[b];
  pi[a] = c * pa + sn * pb;
  pi[b] = -sn * pa + c * pb;
  Quat turn(1, 0, 0, 0);
  turn.vec()[k] = tau;
  q = q * turn;
}

}  // namespace

double bounding_radius(const geometry::ClumpTemplate& clump) {
  double r = 0;
  for (const geometry::ClumpSphere& sphere : clump.spheres) r = std::max(r, sphere.centre.norm() + sphere.radius);
  return r;
}

std::size_t add_clump(State& s, const geometry::ClumpTemplate& clump, double scale, std::int64_t first_id,
                      const Vec3& position, const Quat& q, double density, int material, const Vec3& velocity,
                      const Vec3& angular_velocity) {
  if (!(clump.mesh_volume_m3 > 0) || !(clump.inertia_principal_per_density.minCoeff() > 0) || clump.spheres.empty())
    throw diefill::InputError("clump template", "mesh_volume_m3, inertia_principal_per_density, spheres",
                              "a clump needs spheres and the grain's positive volume and principal moments",
                              "Build the template with `diefill clump` from a closed grain mesh");
  Bodies& B = s.bodies;
  const std::size_t b = B.size();
  const double mass = density * clump.mesh_volume_m3 * scale * scale * scale;
  const Vec3 inertia = density * std::pow(scale, 5) * clump.inertia_principal_per_density;
  const Quat unit = q.normalized();
  B.x.push_back(position);
  B.v.push_back(velocity);
  B.q.push_back(unit);
  B.l.push_back(unit * inertia.cwiseProduct(unit.conjugate() * angular_velocity));
  B.f.push_back(Vec3::Zero());
  B.torque.push_back(Vec3::Zero());
  B.mass.push_back(mass);
  B.inertia.push_back(inertia);
  B.volume.push_back(clump.mesh_volume_m3 * scale * scale * scale);
  B.active.push_back(1);
  if (B.member_start.empty()) B.member_start.push_back(0);
  for (std::size_t k = 0; k < clump.spheres.size(); ++k) {
    s.add_sphere(first_id + std::int64_t(k), position, scale * clump.spheres[k].radius, density, material);
    s.mass.back() = mass;
    s.body.back() = std::int32_t(b);
    B.member.push_back(std::int32_t(s.size() - 1));
    B.offset.push_back(scale * clump.spheres[k].centre);
  }
  B.member_start.push_back(std::int32_t(B.member.size()));
  follow_body(s, b, true);
  return b;
}

void place_members(State& s) {
  for (std::size_t b = 0; b < s.bodies.size(); ++b) follow_body(s, b, true);
}

void sum_body_forces(const Model& model, State& s) {
  Bodies& B = s.bodies;
  const std::size_t n = B.size();
  if (n == 0) return;  // a sphere scene pays no thread start-up for bodies
#pragma omp parallel for schedule(static)
  for (std::size_t b = 0; b < n; ++b) {
    if (!B.active[b]) continue;
    Vec3 f = B.mass[b] * model.gravity, t = Vec3::Zero();
    for (std::int32_t k = B.member_start[b]; k < B.member_start[b + 1]; ++k) {
      const std::size_t i = std::size_t(B.member[std::size_t(k)]);
      f += s.f[i];
      t += (s.x[i] - B.x[b]).cross(s.f[i]) + s.torque[i];
    }
    B.f[b] = f;
    B.torque[b] = t;
  }
}

void kick_bodies(State& s, double h) {
  Bodies& B = s.bodies;
  const std::size_t n = B.size();
  if (n == 0) return;
#pragma omp parallel for schedule(static)
  for (std::size_t b = 0; b < n; ++b) {
    if (!B.active[b]) continue;
    B.v[b] += (h / B.mass[b]) * B.f[b];
    B.l[b] += h * B.torque[b];
    follow_body(s, b, false);
  }
}

void drift_bodies(State& s, double dt) {
  Bodies& B = s.bodies;
  const std::size_t n = B.size();
  if (n == 0) return;
#pragma omp parallel for schedule(static)
  for (std::size_t b = 0; b < n; ++b) {
    if (!B.active[b]) continue;
    B.x[b] += dt * B.v[b];
    // L stays as it is: the free rotor's flow conserves it, and rounding then cannot drift it.
    Vec3 pi = B.q[b].conjugate() * B.l[b];
    Quat q = B.q[b];
    rotate_about_axis(0, 0.5 * dt, B.inertia[b], pi, q);
    rotate_about_axis(1, 0.5 * dt, B.inertia[b], pi, q);
    rotate_about_axis(2, dt, B.inertia[b], pi, q);
    rotate_about_axis(1, 0.5 * dt, B.inertia[b], pi, q);
    rotate_about_axis(0, 0.5 * dt, B.inertia[b], pi, q);
    B.q[b] = q.normalized();
    follow_body(s, b, true);
  }
}

double body_kinetic_energy(const State& s) {
  const Bodies& B = s.bodies;
  double e = 0;
  for (std::size_t b = 0; b < B.size(); ++b)
    if (B.active[b]) e += 0.5 * B.mass[b] * B.v[b].squaredNorm() + 0.5 * B.angular_velocity(b).dot(B.l[b]);
  return e;
}

double body_potential_energy(const Model& model, const State& s) {
  const Bodies& B = s.bodies;
  double e = 0;
  for (std::size_t b = 0; b < B.size(); ++b)
    if (B.active[b]) e -= B.mass[b] * model.gravity.dot(B.x[b]);
  return e;
}

}  // namespace dem
