#include "dem/model.hpp"

#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>

#include "core/error.hpp"
#include "core/log.hpp"
#include "core/sha256.hpp"
#include "dem/dem_source_hash.hpp"
#include "dem/state.hpp"

namespace dem {

std::string_view source_hash() { return DIEFILL_DEM_SOURCE_HASH; }

using diefill::InputError;

namespace {

void check_material(const Material& m, std::size_t k, const std::string& source) {
  const std::string field = fmt::format("materials[{}] ({})", k, m.name);
  auto require = [&](bool ok, const char* key, const std::string& what) {
    if (!ok) throw InputError(source, field + "." + key, what, "Correct the material");
  };
  require(m.density > 0 && std::isfinite(m.density), "density", "must be positive [kg/m³]");
  require(m.youngs_modulus > 0 && std::isfinite(m.youngs_modulus), "youngs_modulus", "must be positive [Pa]");
  require(m.poisson_ratio >= 0 && m.poisson_ratio < 0.5, "poisson_ratio", "must lie in [0, 0.5)");
  require(m.restitution > 0 && m.restitution <= 1, "restitution", "must lie in (0, 1]");
  require(m.sliding_friction >= 0, "sliding_friction", "must not be negative");
  require(m.rolling_friction >= 0, "rolling_friction", "must not be negative");
  require(m.cohesion_energy_density >= 0, "cohesion_energy_density", "must not be negative [J/m³]");
}

double shear_modulus(const Material& m) { return m.youngs_modulus / (2 * (1 + m.poisson_ratio)); }

// Rayleigh wave time of a grain (docs/PHYSICS.md §5).
double rayleigh_time(const Material& m, double radius) {
  return std::numbers::pi * radius * std::sqrt(m.density / shear_modulus(m)) /
         (0.1631 * m.poisson_ratio + 0.8766);
}

// The registry's combination of the scene's four laws, or an error naming the slot whose law is
// unknown, with the ones there are.
const CompiledContactLaw& contact_law_of(const ContactLawChoice& choice, const std::string& source) {
  for (std::size_t k = 0; k < law_slot_names.size(); ++k) {
    const auto slot = LawSlot(k);
    const std::vector<std::string_view> names = slot_law_names(slot);
    if (std::find(names.begin(), names.end(), choice[slot]) == names.end())
      throw InputError(source, fmt::format("contact.{}", law_slot_names[k]), fmt::format("no {} law is called \"{}\"", law_slot_names[k], choice[slot]),
                       fmt::format("Name one of: {}", fmt::join(names, ", ")));
  }
  if (const CompiledContactLaw* law = find_contact_law(choice)) return *law;
  throw InputError(source, "contact", fmt::format("the laws {} + {} + {} + {} are not compiled together", choice.normal, choice.tangential, choice.rolling, choice.cohesion),
                   "Register the combination (docs/ARCHITECTURE.md, \"Adding a contact law\")");
}

// Whether one of the laws declares that it reads this scene key.
bool reads_key(const ContactLawChoice& choice, std::string_view key) {
  for (const SlotLaw& law : slot_laws())
    if (choice[law.slot] == law.name && law.reads.find(key) != std::string_view::npos) return true;
  return false;
}

// Rounding a coordinate c to single precision moves it by at most half the spacing of floats at
// |c|; within the domain that is largest at its farthest corner, on each of the three axes.
double build_position_rounding(const Box3& domain) {
  const auto farthest = float(domain.lo.cwiseAbs().cwiseMax(domain.hi.cwiseAbs()).maxCoeff());
  const double spacing = double(std::nextafter(farthest, std::numeric_limits<float>::infinity())) - double(farthest);
  return std::sqrt(3.0) * 0.5 * spacing;
}

}  // namespace

Model compile_model(const ModelSpec& spec, const State& state, const std::string& source) {
  if (spec.materials.empty())
    throw InputError(source, "materials", "no material is defined", "Add a [[materials]] table");
  for (std::size_t k = 0; k < spec.materials.size(); ++k) check_material(spec.materials[k], k, source);
  const int nm = int(spec.materials.size());
  for (std::size_t i = 0; i < state.size(); ++i)
    if (state.material[i] < 0 || state.material[i] >= nm)
      throw InputError(source, "particles.material", fmt::format("grain {} names material {} of {}", state.id[i], state.material[i], nm),
                       "Give every grain a defined material");
  const CompiledContactLaw& law = contact_law_of(spec.law, source);
  if (reads_key(spec.law, "contact.linear_stiffness") && !(spec.linear_stiffness > 0))
    throw InputError(source, "contact.linear_stiffness", fmt::format("the {} normal law needs a positive stiffness [N/m]", spec.law.normal),
                     "Set contact.linear_stiffness");

  Model m;
  m.materials = spec.materials;
  m.law = spec.law;
  m.contact_law = &law;
  m.gravity = spec.gravity;
  m.domain = spec.domain;
  m.planes = spec.planes;
  m.meshes = spec.meshes;
  m.stop_overlap = spec.stop_overlap;
  for (PlaneWall& p : m.planes) p.normal.normalize();
  for (const MeshWall& w : m.meshes) {
    if (!w.field) throw InputError(source, "walls", "a mesh wall has no distance field", "Give the wall a mesh");
    m.mesh_moves.push_back(w.motion.moves() || w.motion.start_position.squaredNorm() > 0);
    double reach = 0;
    for (const Vec3& v : w.field->vertices) reach = std::max(reach, (v - w.motion.pivot).norm());
    m.mesh_reach.push_back(reach);
  }

  // Pairs: Hertz effective moduli; unlike materials mix e, μ and cohesion by the geometric
  // mean unless an interaction says otherwise.
  m.pair_table.resize(std::size_t(nm * nm));
  std::map<double, double> damping_of;  // calibration is shared by pairs with the same e
  for (int a = 0; a < nm; ++a)
    for (int b = 0; b < nm; ++b) {
      const Material &ma = m.materials[std::size_t(a)], &mb = m.materials[std::size_t(b)];
      PairParams p;
      p.e_star = 1.0 / ((1 - ma.poisson_ratio * ma.poisson_ratio) / ma.youngs_modulus +
                        (1 - mb.poisson_ratio * mb.poisson_ratio) / mb.youngs_modulus);
      p.g_star = 1.0 / ((2 - ma.poisson_ratio) / shear_modulus(ma) + (2 - mb.poisson_ratio) / shear_modulus(mb));
      p.restitution = std::sqrt(ma.restitution * mb.restitution);
      p.mu_s = std::sqrt(ma.sliding_friction * mb.sliding_friction);
      p.mu_r = std::sqrt(ma.rolling_friction * mb.rolling_friction);
      p.cohesion = std::sqrt(ma.cohesion_energy_density * mb.cohesion_energy_density);
      p.k_linear = spec.linear_stiffness;
      p.kt_over_kn = 4.0 * p.g_star / p.e_star;
      p.sqrt_kt_over_kn = std::sqrt(p.kt_over_kn);
      for (const Interaction& it : spec.interactions)
        if ((it.a == a && it.b == b) || (it.a == b && it.b == a)) {
          if (it.restitution) p.restitution = *it.restitution;
          if (it.sliding_friction) p.mu_s = *it.sliding_friction;
          if (it.rolling_friction) p.mu_r = *it.rolling_friction;
        }
      if (!(p.restitution > 0 && p.restitution <= 1))
        throw InputError(source, "interactions.restitution", "must lie in (0, 1]", "Correct the interaction");
      auto it = damping_of.find(p.restitution);
      if (it == damping_of.end()) it = damping_of.emplace(p.restitution, damping_for_restitution(law.unit_force, law.unit_damping, p.restitution)).first;
      p.damping = it->second;
      m.pair_table[std::size_t(a * nm + b)] = p;
    }

  // Time step: a fraction of the smaller of the Rayleigh time and the collision time at the
  // highest expected impact speed, over the grains present.
  m.max_radius = 0;
  m.dt_rayleigh = std::numeric_limits<double>::infinity();
  m.dt_hertz = std::numeric_limits<double>::infinity();
  std::map<std::pair<int, double>, bool> seen;
  for (std::size_t i = 0; i < state.size(); ++i) {
    m.max_radius = std::max(m.max_radius, state.radius[i]);
    if (!seen.emplace(std::pair{state.material[i], state.radius[i]}, true).second) continue;
    const Material& mat = m.materials[std::size_t(state.material[i])];
    m.dt_rayleigh = std::min(m.dt_rayleigh, rayleigh_time(mat, state.radius[i]));
    for (int b = 0; b < nm; ++b) {
      const PairParams& p = m.params(state.material[i], b);
      const double v = std::max(spec.max_impact_speed, 1e-3);
      // Against an equal grain, and against a wall (R* = r, m* = m).
      const double r = state.radius[i], mass = state.mass[i];
      m.dt_hertz = std::min({m.dt_hertz, law.collision_time(p, r / 2, mass / 2, v), law.collision_time(p, r, mass, v)});
    }
  }
  // Split over ranks, each holds some of the grains: the time step is the whole scene's.
  if (state.exchange) {
    m.max_radius = state.exchange->max(m.max_radius);
    m.dt_rayleigh = -state.exchange->max(-m.dt_rayleigh);
    m.dt_hertz = -state.exchange->max(-m.dt_hertz);
  }
  const double stable = std::min(m.dt_rayleigh, m.dt_hertz);
  if (spec.time_step) {
    if (!(*spec.time_step > 0))
      throw InputError(source, "simulation.time_step", "must be positive or \"auto\"", "Give seconds or \"auto\"");
    m.dt = *spec.time_step;
    if (std::isfinite(stable) && m.dt > 0.3 * stable)
      diefill::log::warn("{}: simulation.time_step {:.3g} s is {:.2g} of the stable limit {:.3g} s (Rayleigh {:.3g} s, "
                         "collision {:.3g} s); expect overlaps and energy growth beyond about 0.3",
                         source, m.dt, m.dt / stable, stable, m.dt_rayleigh, m.dt_hertz);
  } else {
    m.dt = std::isfinite(stable) ? spec.time_step_fraction * stable : 1e-5;
  }
  m.skin = spec.skin ? *spec.skin : 0.5 * m.max_radius;
  if (!(m.skin > 0))
    throw InputError(source, "simulation.skin", "must be positive [m]", "Give a skin of about half a grain radius");
  // The list is checked every step, so a grain may move at most half the skin per step.
  if (spec.max_impact_speed * m.dt > 0.5 * m.skin)
    diefill::log::warn("{}: at {:.3g} m/s a grain moves {:.3g} m per step, more than half the neighbour skin "
                       "{:.3g} m: contacts could be missed. Lower the time step or widen the skin",
                       source, spec.max_impact_speed, spec.max_impact_speed * m.dt, m.skin);
  // A wall's motion is known exactly, so a wall that could pass grains unseen is refused. A
  // rotating wall's points move by up to |ω| times their distance from the pivot on top.
  for (std::size_t k = 0; k < spec.meshes.size(); ++k) {
    const MeshWall& w = spec.meshes[k];
    check_wall_travel(w.name, w.motion.top_speed() + w.motion.angular_velocity.norm() * m.mesh_reach[k], m.dt, m.skin, source);
  }
  m.build_position_rounding = build_position_rounding(m.domain);
  // It takes its share of the half skin from every grain's travel between rebuilds.
  if (m.build_position_rounding > 0.1 * m.skin)
    throw InputError(source, "domain", fmt::format("a box reaching {:.3g} m from the origin holds positions to only {:.3g} m in "
                                                   "the neighbour list's single precision, over a tenth of the skin {:.3g} m",
                                                   m.domain.lo.cwiseAbs().cwiseMax(m.domain.hi.cwiseAbs()).maxCoeff(),
                                                   m.build_position_rounding, m.skin),
                     "Place the scene near the origin and give a domain that just holds it");
  m.cell_size = 2 * m.max_radius + m.skin;

  std::string text = fmt::format("dt={:a};skin={:a};g={:a},{:a},{:a};laws={}+{}+{}+{};stop={:a};dom={:a},{:a},{:a},{:a},{:a},{:a}",
                                 m.dt, m.skin, m.gravity.x(), m.gravity.y(), m.gravity.z(), m.law.normal,
                                 m.law.tangential, m.law.rolling, m.law.cohesion, m.stop_overlap,
                                 m.domain.lo.x(), m.domain.lo.y(), m.domain.lo.z(), m.domain.hi.x(),
                                 m.domain.hi.y(), m.domain.hi.z());
  for (const PairParams& p : m.pair_table)
    text += fmt::format(";{:a},{:a},{:a},{:a},{:a},{:a},{:a}", p.e_star, p.g_star, p.damping, p.mu_s, p.mu_r, p.k_linear, p.cohesion);
  for (const PlaneWall& p : m.planes)
    text += fmt::format(";plane{:a},{:a},{:a},{:a},{:a},{:a},{}", p.point.x(), p.point.y(), p.point.z(), p.normal.x(), p.normal.y(), p.normal.z(), p.material);
  // The walls' motion is part of the model: a checkpoint resumes only under the same one.
  const auto vec = [](const Vec3& v) { return fmt::format("{:a},{:a},{:a}", v.x(), v.y(), v.z()); };
  for (const MeshWall& w : m.meshes) {
    text += fmt::format(";mesh{},{},{},{},{:a},{:a},{:a}", w.name, w.field->triangles.size(), w.field->voxel, w.material,
                        w.cut_z, w.cut_fraction, w.cut_cap);
    text += fmt::format(";motion{};{};{};{}", vec(w.motion.start_position), vec(w.motion.start_velocity),
                        vec(w.motion.angular_velocity), vec(w.motion.pivot));
    for (const Motion::Segment& seg : w.motion.segments) text += fmt::format(";{:a},{}", seg.duration, vec(seg.acceleration));
  }
  m.hash = diefill::sha256_hex(text);
  return m;
}

void check_wall_travel(const std::string& name, double top_speed, double dt, double skin, const std::string& source) {
  if (const double per_step = top_speed * dt; per_step > 0.5 * skin)
    throw InputError(source, "walls." + name + ".motion",
                     fmt::format("the wall moves {:.3g} m per step at its top speed {:.3g} m/s, more than half the neighbour "
                                 "skin {:.3g} m: it could pass through grains it has not listed",
                                 per_step, top_speed, skin),
                     "Lower the wall's speed or the time step, or widen simulation.skin");
}

}  // namespace dem
