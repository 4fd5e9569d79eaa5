#pragma once
// Rigid multi-sphere clumps (State::bodies): creation from a template, the body sums after the
// force stage, and the body half of the integrator. Translation is velocity Verlet like the
// spheres'; rotation is the symplectic splitting of Dullweber, Leimkuhler & McLachlan (J. Chem.
// Phys. 107, 5840, 1997): the free rotor's flow is composed of rotations about the principal
// axes, in the symmetric order 1, 2, 3, 2, 1, so that a free body keeps its angular momentum
// exactly and its energy to second order without drift, and an intermediate-axis spin flips as
// it should.
#include <cstdint>

#include "dem/model.hpp"
#include "dem/state.hpp"
#include "geometry/clump_template.hpp"

namespace dem {

// Appends a clump of `clump` scaled by `scale`, centre at `position`, orientation `q`
// (principal frame to world), members with ids first_id, first_id + 1, ...; mass and inertia
// from the grain (density × mesh volume, density × principal moments). Returns the body index.
// Throws InputError for a template without spheres, volume or moments.
std::size_t add_clump(State& state, const geometry::ClumpTemplate& clump, double scale, std::int64_t first_id,
                      const Vec3& position, const Quat& q, double density, int material,
                      const Vec3& velocity = Vec3::Zero(), const Vec3& angular_velocity = Vec3::Zero());

// Radius of the sphere about the centre that holds every member [m], before scaling.
double bounding_radius(const geometry::ClumpTemplate& clump);

// Members' positions and velocities from their bodies' poses and velocities: after setting a
// body's state by hand.
void place_members(State& state);

// Each body's force (its members' plus gravity) and torque about its centre, members in order.
void sum_body_forces(const Model& model, State& state);
// v += h F/M, L += h T; then the members' velocities.
void kick_bodies(State& state, double h);
// Centre and orientation over dt; then the members' positions and velocities.
void drift_bodies(State& state, double dt);

// Σ ½MV² + ½ω·L and Σ −M g·X over active bodies [J].
double body_kinetic_energy(const State& state);
double body_potential_energy(const Model& model, const State& state);

}  // namespace dem
