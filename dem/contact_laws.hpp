#pragma once
// The contact-law registry: which law each of a contact's four slots (normal, tangential, rolling,
// cohesion) may take, by name, and the force kernels compiled for each combination. A scene names
// one law per slot (contact.normal = "hertz", ...); the model looks the combination up here. The
// built-in laws (contact.hpp) are registered in every combination (forces.cpp); another law is one
// file holding its struct and a RegisterContactLaw line (force_kernels.hpp; docs/ARCHITECTURE.md,
// "Adding a contact law"). Light: the kernels themselves stay in force_kernels.hpp.
#include <array>
#include <string>
#include <string_view>
#include <vector>

namespace dem {

struct Model;
struct State;
struct PairParams;

enum class LawSlot { normal, tangential, rolling, cohesion };
inline constexpr std::array<std::string_view, 4> law_slot_names = {"normal", "tangential", "rolling", "cohesion"};

// A scene's choice: one law's name per slot.
struct ContactLawChoice {
  std::string normal = "hertz", tangential = "mindlin", rolling = "none", cohesion = "none";
  std::string& operator[](LawSlot slot) {
    return slot == LawSlot::normal ? normal : slot == LawSlot::tangential ? tangential : slot == LawSlot::rolling ? rolling : cohesion;
  }
  const std::string& operator[](LawSlot slot) const { return (*const_cast<ContactLawChoice*>(this))[slot]; }
};

// What a law declares (its struct's name, meaning, reads and keeps_history; contact.hpp).
struct SlotLaw {
  LawSlot slot;
  std::string_view name, meaning, reads;
  bool keeps_history;  // a per-contact history the neighbour list stores and carries
};

// One registered combination: its force kernels and what the model needs of its normal law.
struct CompiledContactLaw {
  ContactLawChoice choice;
  void (*pair_forces)(const Model&, State&);
  void (*wall_forces)(const Model&, State&);
  bool keeps_tangential, keeps_rolling;  // the histories its slots keep
  double (*collision_time)(const PairParams&, double r_eff, double m_eff, double speed);
  double (*elastic_energy)(const PairParams&, double r_eff, double overlap);
  double (*unit_force)(double), (*unit_damping)(double);
};

// Every slot law registered, in registration order (built-ins first).
const std::vector<SlotLaw>& slot_laws();
std::vector<std::string_view> slot_law_names(LawSlot slot);
// The compiled combination, or nullptr.
const CompiledContactLaw* find_contact_law(const ContactLawChoice& choice);
// Adds a combination and its slots' laws (a law already listed under its name is not listed
// twice). RegisterContactLaw (force_kernels.hpp) calls it.
void register_contact_law(const CompiledContactLaw& law, const std::array<SlotLaw, 4>& slots);

}  // namespace dem
