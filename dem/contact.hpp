#pragma once
// Contact laws composed of slots (after LAMMPS GRANULAR): normal (Hertz or linear
// spring-dashpot, each with viscous damping to a prescribed restitution), tangential (Mindlin
// spring with history and a Coulomb cap), rolling (elastic-plastic spring or constant
// directional torque) and cohesion (simplified JKR). Each slot's law is a small struct: a pure
// function, and what the registry (contact_laws.hpp) reads of it: its name in scenes
// (contact.<slot>), what it does, the scene keys it reads, and whether it keeps a history per
// contact. The force loop is instantiated once per combination registered (forces.cpp), so adding
// a law never touches the loop (docs/ARCHITECTURE.md, "Adding a contact law"). Equations:
// docs/PHYSICS.md §2.
// The laws choose by selection, not by branches: the pair loop evaluates them over batches of
// contacts that the compiler vectorises (one contact per lane, the same IEEE operations as one
// at a time), which a branch would forbid.
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string_view>

#include "dem/types.hpp"

namespace dem {

// Parameters of one pair of materials (or a material and a wall), after mixing. SI units.
struct PairParams {
  double e_star = 0;       // effective Young's modulus E* [Pa]
  double g_star = 0;       // effective shear modulus G* [Pa]
  double restitution = 1;  // prescribed e
  double damping = 0;      // dimensionless damping ratio, calibrated so the realised e is the prescribed one
  double mu_s = 0;         // sliding friction
  double mu_r = 0;         // rolling friction (dimensionless)
  double k_linear = 0;     // linear normal stiffness [N/m] (linear law)
  double kt_over_kn = 0;   // tangential over normal stiffness, 4 G*/E* (Mindlin: S_t = 8 G* a, S_n = 2 E* a)
  double sqrt_kt_over_kn = 0;
  double cohesion = 0;     // SJKR cohesion energy density [J/m³ = N/m²]
};


// Geometry and kinematics of one contact, from body i's point of view: n points from j to i.
struct ContactKinematics {
  Vec3 n;            // unit normal, from the partner towards body i
  double overlap;    // δ > 0 [m]
  double r_eff;      // R* [m]
  double m_eff;      // m* [kg]
  Vec3 v_rel;        // velocity of i relative to the partner at the contact point [m/s]
  Vec3 w_rel;        // angular velocity of i relative to the partner [rad/s] (rolling)
};

// What a contact carries between steps, per pair.
struct ContactHistory {
  Vec3 tangential = Vec3::Zero();  // accumulated tangential displacement ξ [m]
  Vec3 rolling = Vec3::Zero();     // elastic rolling torque (EPSD) [N m]
};

struct ContactForce {
  Vec3 force;           // on body i [N]
  Vec3 rolling_torque;  // on body i [N m] (the partner gets the opposite)
  double normal;        // magnitude of the repulsive normal force [N]
};

// ---- normal slot ------------------------------------------------------------------------
// eval: the elastic normal force [N] and the normal stiffness S_n [N/m] at this overlap. Besides,
// a normal law gives the model its time step and damping: the collision time at an impact speed,
// the stored elastic energy, and the dimensionless collision (contact.cpp: force f(x) and damping
// shape g(x) at overlap x, time in units of sqrt(m*/k) or its Hertz equivalent).
struct HertzNormal {
  static constexpr std::string_view name = "hertz", meaning = "Hertz",
                                    reads = "materials' youngs_modulus and poisson_ratio";
  static constexpr bool keeps_history = false;
  // 2.9432 δmax / v, δmax = (15 m* v² / (16 E* √R*))^(2/5).
  static double collision_time(const PairParams& p, double r_eff, double m_eff, double speed) {
    const double overlap = std::pow(15 * m_eff * speed * speed / (16 * p.e_star * std::sqrt(r_eff)), 0.4);
    return 2.9432 * overlap / speed;
  }
  static double energy(const PairParams& p, double r_eff, double overlap) {  // (8/15) E* sqrt(R*) δ^{5/2}
    return (8.0 / 15.0) * p.e_star * std::sqrt(r_eff) * overlap * overlap * std::sqrt(overlap);
  }
  static double unit_force(double x) { return (4.0 / 3.0) * x * std::sqrt(x); }
  static double unit_damping(double x) { return std::sqrt(2.0) * std::sqrt(std::sqrt(x)); }
  static void eval(const PairParams& p, const ContactKinematics& c, double& elastic, double& stiffness) {
    const double a = std::sqrt(c.r_eff * c.overlap);   // contact radius [m]
    stiffness = 2.0 * p.e_star * a;                    // S_n = 2 E* sqrt(R* δ)
    elastic = (2.0 / 3.0) * stiffness * c.overlap;     // (4/3) E* sqrt(R*) δ^{3/2}
  }
};
struct LinearNormal {
  static constexpr std::string_view name = "linear", meaning = "a linear spring", reads = "contact.linear_stiffness";
  static constexpr bool keeps_history = false;
  static double collision_time(const PairParams& p, double, double m_eff, double) {
    return std::numbers::pi * std::sqrt(m_eff / p.k_linear);
  }
  static double energy(const PairParams& p, double, double overlap) { return 0.5 * p.k_linear * overlap * overlap; }
  static double unit_force(double x) { return x; }
  static double unit_damping(double) { return 1.0; }
  static void eval(const PairParams& p, const ContactKinematics& c, double& elastic, double& stiffness) {
    stiffness = p.k_linear;
    elastic = p.k_linear * c.overlap;
  }
};

// ---- tangential slot --------------------------------------------------------------------
struct MindlinTangential {
  static constexpr std::string_view name = "mindlin", meaning = "a tangential spring with a Coulomb cap (Mindlin)",
                                    reads = "materials' sliding_friction";
  static constexpr bool keeps_history = true;  // the spring ξ
  // Tangential force on i, updating the spring ξ. S_t = 8 G* sqrt(R* δ) = (4 G*/E*) S_n, damped
  // like the normal part (γ_t = sqrt(S_t/S_n) γ_n); `normal_force` (non-negative) sets the
  // Coulomb cap.
  static Vec3 eval(const PairParams& p, const ContactKinematics& c, double normal_force,
                   double normal_stiffness, double normal_gamma, double dt, Vec3& spring) {
    const Vec3 vt = c.v_rel - c.n * c.n.dot(c.v_rel);
    // Keep the spring in the current tangent plane. Its length is not restored: the rotation
    // per step is of order 1e-4 rad, so the length lost is of order 1e-8 per step.
    spring -= c.n * c.n.dot(spring);
    spring += vt * dt;
    const double kt = p.kt_over_kn * normal_stiffness;
    Vec3 force = -kt * spring - (p.sqrt_kt_over_kn * normal_gamma) * vt;
    const double cap = p.mu_s * normal_force;
    const double magnitude2 = force.squaredNorm();
    // Gross sliding: the force sits on the Coulomb cap and the spring is reset to it.
    const bool sliding = magnitude2 > cap * cap;
    force *= sliding ? cap / std::sqrt(magnitude2) : 1.0;
    const double kt_or_one = kt > 0 ? kt : 1.0;
    for (int k = 0; k < 3; ++k)
      spring[k] = sliding ? (kt > 0 ? -force[k] / kt_or_one : 0.0) : spring[k];
    return force;
  }
};
struct NoTangential {
  static constexpr std::string_view name = "none", meaning = "frictionless", reads = "";
  static constexpr bool keeps_history = false;
  static Vec3 eval(const PairParams&, const ContactKinematics&, double, double, double, double, Vec3&) {
    return Vec3::Zero();
  }
};

// ---- rolling slot -----------------------------------------------------------------------
// Torque on i opposing the relative rolling; limit μ_r R* F_n.
struct EpsdRolling {
  static constexpr std::string_view name = "epsd", meaning = "an elastic-plastic spring", reads = "materials' rolling_friction";
  static constexpr bool keeps_history = true;  // the elastic torque
  // Elastic-plastic spring (Ai et al. 2011, type C without damping): k_r = 2.25 S_n μ_r² R*².
  static Vec3 eval(const PairParams& p, const ContactKinematics& c, double normal_force,
                   double normal_stiffness, double dt, Vec3& torque) {
    const Vec3 w_roll = c.w_rel - c.n * c.n.dot(c.w_rel);
    torque -= c.n * c.n.dot(torque);  // into the tangent plane, as the tangential spring
    const double kr = 2.25 * normal_stiffness * p.mu_r * p.mu_r * c.r_eff * c.r_eff;
    torque -= kr * w_roll * dt;
    const double cap = p.mu_r * c.r_eff * normal_force;
    const double magnitude2 = torque.squaredNorm();
    torque *= magnitude2 > cap * cap ? cap / std::sqrt(magnitude2) : 1.0;
    return torque;
  }
};
struct CdtRolling {
  static constexpr std::string_view name = "cdt", meaning = "a constant directional torque", reads = "materials' rolling_friction";
  static constexpr bool keeps_history = false;
  // Constant directional torque (LIGGGHTS "cdt"): full limit against the rolling direction.
  static Vec3 eval(const PairParams& p, const ContactKinematics& c, double normal_force, double,
                   double, Vec3&) {
    const Vec3 w_roll = c.w_rel - c.n * c.n.dot(c.w_rel);
    const double w = w_roll.norm();
    const double w_or_one = w < 1e-12 ? 1.0 : w;
    return -(w < 1e-12 ? 0.0 : p.mu_r * c.r_eff * normal_force / w_or_one) * w_roll;
  }
};
struct NoRolling {
  static constexpr std::string_view name = "none", meaning = "no resistance (spheres need one for 30-40° repose)", reads = "";
  static constexpr bool keeps_history = false;
  static Vec3 eval(const PairParams&, const ContactKinematics&, double, double, double, Vec3&) {
    return Vec3::Zero();
  }
};

// ---- cohesion slot ----------------------------------------------------------------------
// Simplified JKR: an attractive force k A over the Hertzian contact area A = π R* δ.
struct SjkrCohesion {
  static constexpr std::string_view name = "sjkr", meaning = "simplified JKR", reads = "materials' cohesion_energy_density";
  static constexpr bool keeps_history = false;
  static double eval(const PairParams& p, const ContactKinematics& c) {
    return -p.cohesion * 3.14159265358979323846 * c.r_eff * c.overlap;
  }
};
struct NoCohesion {
  static constexpr std::string_view name = "none", meaning = "no cohesion", reads = "";
  static constexpr bool keeps_history = false;
  static double eval(const PairParams&, const ContactKinematics&) { return 0.0; }
};

// The composed law: normal elastic plus damping (never attractive), cohesion, tangential and
// rolling, in that order.
template <class Normal, class Tangential, class Rolling, class Cohesion>
struct ContactLaw {
  using NormalSlot = Normal;
  // The histories the pair loop gathers and stores (only those, contact.hpp's ContactHistory).
  static constexpr bool keeps_tangential = Tangential::keeps_history, keeps_rolling = Rolling::keeps_history;
  static_assert(!Normal::keeps_history && !Cohesion::keeps_history, "a contact keeps a tangential and a rolling history only");
  static ContactForce eval(const PairParams& p, const ContactKinematics& c, double dt,
                           ContactHistory& h) {
    double elastic, stiffness;
    Normal::eval(p, c, elastic, stiffness);
    const double vn = c.n.dot(c.v_rel);  // > 0 when separating
    const double gamma = p.damping * std::sqrt(stiffness * c.m_eff);
    // Contact force in the normal direction without cohesion may not pull.
    const double repulsive = std::max(0.0, elastic - gamma * vn);
    const double normal = repulsive + Cohesion::eval(p, c);
    ContactForce out;
    out.normal = repulsive;
    out.force = c.n * normal;
    out.force += Tangential::eval(p, c, repulsive, stiffness, gamma, dt, h.tangential);
    out.rolling_torque = Rolling::eval(p, c, repulsive, stiffness, dt, h.rolling);
    return out;
  }
};

// The restitution a damping ratio gives under a normal law: one dimensionless collision at unit
// approach speed, x'' = -max(0, f(x) + damping g(x) x'), integrated (with the no-pull clamp).
double restitution_for_damping(double (*unit_force)(double), double (*unit_damping)(double), double damping);
// Its inverse by bisection: the damping ratio γ / sqrt(S_n m*) that makes a collision end with
// restitution `e`.
double damping_for_restitution(double (*unit_force)(double), double (*unit_damping)(double), double e);

}  // namespace dem
