#pragma once
// Everything that changes while stepping. Particles are a structure of arrays; the neighbour
// list is a half list (j > i) in compressed rows, with each pair's contact history beside it
// and per-pair force buffers, so that per-particle sums run in a fixed order whatever the
// thread count (bit-identical results). Shapes: N particles, P listed pairs, K wall slots,
// B rigid bodies (clumps) with M members in all.
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "dem/contact.hpp"
#include "dem/exchange.hpp"
#include "dem/types.hpp"

namespace dem {

inline constexpr int wall_slots_per_particle = 4;  // K: contacts one grain keeps with walls

struct WallSlot {
  std::int32_t wall = -1;  // planes first, then mesh walls; -1: empty
  std::int32_t unused = 0;  // the padding, named: a checkpoint writes slots as bytes, the same state the same bytes
  Vec3 normal = Vec3::Zero();  // last contact normal, to recognise the contact next step
  ContactHistory history;
};

// Where a grain's wall queries start, per mesh wall: the closest triangles of the voxel cell it
// was in, each moved on to where its walk to a local minimum ended, with watches where a walk
// left a surface over a sharp edge (geometry::WallField::local_minima_tracked), so that a query walks
// over a triangle or none instead of a voxel's worth of them: the wall cost does not grow with
// the tessellation. Read afresh from the voxels when the grain is a quarter voxel beyond the cell
// (dem/walls.cpp) and at every neighbour build, when grains migrate between ranks. Part of the
// state, and of the checkpoint: where a concave tessellated wall holds minima on neighbouring
// facets a tracked query may keep another than a fresh one would (docs/ARCHITECTURE.md, "Walls as
// signed-distance fields").
struct WallCandidates {
  std::array<int, 3> cell{};
  std::int32_t count = -1;  // -1: not filled yet
  std::int32_t triangles[8];  // a triangle to walk from, or ~t: a watch on triangle t
};

// The half neighbour list (j > i) in compressed rows, with each pair's contact history beside
// it. Particles are sorted along a space-filling curve at every build and split into blocks of
// consecutive particles (block_size, a function of N only): a pair within a block adds its
// partner's share to the partner directly, in row order; a pair reaching into a later block
// ("cross" pair) writes the share to a buffer, summed per partner afterwards in pair order. Every
// grain's force is therefore summed in one fixed order, whatever the thread count, and only the
// cross pairs need buffers (docs/ARCHITECTURE.md, "Model and state").
struct NeighbourList {
  Array<std::int32_t> row_start;      // [N+1] pairs of particle i: [row_start[i], row_start[i+1])
  Array<std::int32_t> partner;        // [P] j > i
  Array<Vec3f> tangential;            // [P] Mindlin spring ξ [m]; empty without tangential friction
  Array<Vec3f> rolling;               // [P] EPSD torque [N m]; empty unless the rolling law is EPSD
  Array<std::uint8_t> touching;       // [P] 1 while the pair is in contact
  std::int32_t block_size = 1;              // particles per block
  Array<std::int32_t> cross_start;    // [N+1] cross pairs of row i: buffer slots [cross_start[i], cross_start[i+1])
  Array<std::int32_t> cross_reverse_start;  // [N+1] cross slots naming particle j as partner
  Array<std::int32_t> cross_reverse;  // [C] those slots, ascending
  Array<std::int32_t> near_wall;      // particles within range of a wall at build time
  Array<Vec3f> x_at_build;            // [N] [m], rounded (Model::build_position_rounding)
  Array<Vec3> wall_shift_at_build;    // [mesh walls] [m] wall origin at build time
  double time_at_build = 0;                 // [s]
  std::int64_t builds = 0;

  std::size_t blocks() const { return (row_start.size() - 1 + std::size_t(block_size) - 1) / std::size_t(block_size); }
};

// The partner's share of each cross pair's force, written by the row owner and summed per
// partner afterwards in a fixed order.
struct CrossForces {
  Array<Vec3> force;   // [C] on j [N]
  Array<Vec3> torque;  // [C] on j [N m]
};

// Rigid multi-sphere clumps. Members are ordinary particles, so that contacts between clumps,
// their histories and wall contacts need no code of their own; the body owns the motion: its
// members are never integrated as free spheres but placed from the pose after each update. A
// body lists its members in template order (particles are re-sorted at every neighbour
// rebuild, so `member` is remapped then), and its force and torque are summed in that order:
// the same bits for any thread count. Angular momentum is kept in the world frame, where a free
// body's stays constant exactly; mass and inertia are the grain's, not the spheres'.
struct Bodies {
  Array<Vec3> x;              // [B] centre of mass [m]
  Array<Vec3> v;              // [B] [m/s]
  Array<Quat> q;              // [B] unit, principal frame to world
  Array<Vec3> l;              // [B] angular momentum about the centre, world frame [kg m²/s]
  Array<Vec3> f;              // [B] [N], gravity included
  Array<Vec3> torque;         // [B] about the centre, world frame [N m]
  Array<double> mass;         // [B] [kg]
  Array<Vec3> inertia;        // [B] principal moments, ascending [kg m²]
  Array<double> volume;       // [B] of the grain (not of the spheres' union) [m³]
  Array<std::uint8_t> active; // [B] 0: lost with its members
  Array<std::int32_t> member_start;  // [B+1] members of b: [member_start[b], member_start[b+1])
  Array<std::int32_t> member;        // [M] particle index
  Array<Vec3> offset;                // [M] member centre in the principal frame [m]

  std::size_t size() const { return x.size(); }
  // World angular velocity ω = R I⁻¹ Rᵀ L [rad/s].
  Vec3 angular_velocity(std::size_t b) const { return q[b] * (q[b].conjugate() * l[b]).cwiseQuotient(inertia[b]); }
};

struct StepCounters {
  double max_overlap_rel = 0;   // largest δ/R this step
  std::int64_t contacts = 0;    // pair contacts this step
  std::int64_t wall_contacts = 0;
  double wall_power = 0;        // power walls deliver to particles [W]
  // At the last energy check (every few hundred steps): the mechanical energy beyond what gravity
  // and the walls can have given, over the energy scale Σ m g r; negative while energy is lost.
  double energy_gain = 0;
  // A step checks the step before it, with the values every rank sent to its one collective
  // (dem/step.cpp): the largest δ/R of that step over the ranks, and whether any rank was asked
  // to stop (stop_asked, set by the caller before the step) so that all stop after the same step.
  double checked_overlap_rel = 0;
  bool stop_asked = false, stop_agreed = false;
};

// A free grain's moment of inertia [kg m²]: a solid sphere's, from its mass and radius rather than
// kept per grain (a clump member's motion is its body's, which keeps its own).
inline double sphere_inertia(double mass, double radius) { return 0.4 * mass * radius * radius; }

struct State {
  // Particles [N]
  Array<std::int64_t> id;
  Array<Vec3> x;          // position [m]
  Array<Vec3> v;          // velocity [m/s]
  Array<Vec3> w;          // angular velocity [rad/s]
  Array<Vec3> f;          // force [N]
  Array<Vec3> torque;     // [N m]
  Array<double> radius;   // [m]
  Array<double> mass;     // [kg]; a clump member's is its body's, for the contact laws
  Array<std::int32_t> material;
  Array<std::uint8_t> active;  // 0: lost (left the domain), no longer simulated
  Array<std::int32_t> body;    // index into `bodies`; -1: a free sphere
  Array<WallSlot> wall_slots;  // [near-wall grains x K], in the order of neighbours.near_wall

  Bodies bodies;

  NeighbourList neighbours;
  CrossForces cross_forces;
  StepCounters counters;
  Array<double> scratch_wall_power;  // [near-wall grains], summed serially
  Array<WallCandidates> wall_candidates;  // [near-wall grains x mesh walls], see walls.hpp

  // Split over MPI ranks (exchange.hpp): the last `ghosts` particles are copies of other ranks'
  // grains, never integrated; the contact histories that came with migrated grains wait in
  // carried_pairs for the next list build.
  std::shared_ptr<Exchange> exchange;
  std::size_t ghosts = 0;
  std::vector<CarriedPair> carried_pairs;
  // After a migration, until the next build: the new index of each grain of the list built before
  // it (-1: it left, or was a ghost), so that the pairs of two grains that stayed keep their
  // histories from that list by index (the others' come by id, in carried_pairs).
  std::vector<std::int32_t> renumbered;

  double time = 0;              // [s]
  std::int64_t step = 0;
  std::int64_t lost = 0;        // particles that left the domain
  double wall_work = 0;         // energy walls delivered to this rank's particles so far [J]
  double energy_reference = 0;  // mechanical energy at initialize() [J]
  double energy_scale = 0;      // Σ m g r: the energy of a grain-radius drop of every grain [J]
  bool energy_reference_set = false;
  // The largest overlap over the radius and the largest energy gain of the run loop so far
  // (pipeline/run_loop.hpp), here so that a checkpoint carries them: a resumed run reports its
  // whole run, not only what followed the resume.
  double loop_max_overlap_rel = 0, loop_max_energy_gain = 0;

  std::size_t size() const { return x.size(); }
  std::size_t owned() const { return x.size() - ghosts; }
  // Every array's allocation [bytes], for the benchmarks' bytes per particle.
  std::size_t memory_bytes() const;
  // Appends a sphere; density in kg/m³.
  void add_sphere(std::int64_t particle_id, const Vec3& position, double r, double density,
                  int material_index, const Vec3& velocity = Vec3::Zero(),
                  const Vec3& angular_velocity = Vec3::Zero());
};

}  // namespace dem
