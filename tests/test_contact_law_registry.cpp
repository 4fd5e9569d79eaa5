// A contact law of the tests' own, added as any new law is (docs/ARCHITECTURE.md, "Adding a
// contact law"): its slot's struct and one registration line, in this file only. It runs through
// the same compiled kernels as the built-in laws, for grain pairs and for walls.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string_view>

#include "core/error.hpp"
#include "dem/force_kernels.hpp"
#include "dem_support.hpp"

using dem::Vec3;

namespace {

// A cohesion of constant pull while two bodies touch: the materials' cohesion energy density k
// times π R*², a force [N] that does not depend on the overlap, so that a grain held by it on a
// Hertz contact rests where (4/3) E* √R* δ^{3/2} = k π R*².
struct ConstantPullCohesion {
  static constexpr std::string_view name = "test_constant_pull", meaning = "a constant pull while touching (a test's law)",
                                    reads = "materials' cohesion_energy_density";
  static constexpr bool keeps_history = false;
  static double eval(const dem::PairParams& p, const dem::ContactKinematics& c) {
    return -p.cohesion * std::numbers::pi * c.r_eff * c.r_eff;
  }
};

const dem::RegisterContactLaw<dem::HertzNormal, dem::NoTangential, dem::NoRolling, ConstantPullCohesion> constant_pull_law;

constexpr double grain_r = 1e-3;

dem::Material cohesive(dem::Material m, double k) {
  m.cohesion_energy_density = k;
  return m;
}

// The overlap a Hertz contact of E* and R* holds against a constant pull F.
double equilibrium_overlap(double e_star, double r_eff, double pull) {
  return std::pow(3 * pull / (4 * e_star * std::sqrt(r_eff)), 2.0 / 3.0);
}

double e_star_of(const dem::Material& a, const dem::Material& b) {
  return 1 / ((1 - a.poisson_ratio * a.poisson_ratio) / a.youngs_modulus + (1 - b.poisson_ratio * b.poisson_ratio) / b.youngs_modulus);
}

dem::ModelSpec pull_spec(std::vector<dem::Material> materials) {
  dem::ModelSpec spec = test::spec_with(std::move(materials));
  spec.law = {"hertz", "none", "none", "test_constant_pull"};
  return spec;
}

}  // namespace

TEST(ContactLawRegistry, ListsALawRegisteredInAnotherFileAfterTheBuiltIns) {
  const std::vector<std::string_view> names = dem::slot_law_names(dem::LawSlot::cohesion);
  EXPECT_EQ(names, (std::vector<std::string_view>{"sjkr", "none", "test_constant_pull"}));
  EXPECT_NE(dem::find_contact_law({"hertz", "none", "none", "test_constant_pull"}), nullptr);
  EXPECT_EQ(dem::find_contact_law({"linear", "none", "none", "test_constant_pull"}), nullptr);  // not registered
}

// Two grains, no gravity, start touching at rest; the law's pull draws them together until the
// Hertz force balances it (damped by a restitution of 0.3).
TEST(ContactLawRegistry, ANewCohesionLawHoldsAGrainPairAtItsClosedFormOverlap) {
  const double k = 2e3;  // [J/m³]
  const dem::Material glass = cohesive(test::glass(0.3), k);
  dem::ModelSpec spec = pull_spec({glass});
  dem::State s;
  s.add_sphere(0, Vec3(0, 0, -grain_r + 1e-9), grain_r, 2500, 0);
  s.add_sphere(1, Vec3(0, 0, grain_r - 1e-9), grain_r, 2500, 0);
  const dem::Model model = dem::compile_model(spec, s, "test");
  dem::initialize(model, s);
  for (int n = 0; n < 40000; ++n) dem::step(model, s);
  const double r_eff = grain_r / 2;
  const double expected = equilibrium_overlap(e_star_of(glass, glass), r_eff, k * std::numbers::pi * r_eff * r_eff);
  const double overlap = 2 * grain_r - (s.x[1] - s.x[0]).norm();
  std::printf("pair: equilibrium overlap %.4g m, closed form %.4g m\n", overlap, expected);
  EXPECT_NEAR(overlap / expected, 1.0, 0.01);
}

// The same law through the wall kernel: a grain held on a floor.
TEST(ContactLawRegistry, ANewCohesionLawHoldsAGrainOnAWallAtItsClosedFormOverlap) {
  const double k = 2e3;
  const dem::Material glass = cohesive(test::glass(0.3), k), wall = cohesive(test::rigid_wall(0.3), k);
  dem::ModelSpec spec = pull_spec({glass, wall});
  spec.planes.push_back({Vec3::Zero(), Vec3::UnitZ(), 1, "floor"});
  dem::State s;
  s.add_sphere(0, Vec3(0, 0, grain_r - 1e-9), grain_r, 2500, 0);
  const dem::Model model = dem::compile_model(spec, s, "test");
  dem::initialize(model, s);
  for (int n = 0; n < 40000; ++n) dem::step(model, s);
  const double expected = equilibrium_overlap(e_star_of(glass, wall), grain_r, k * std::numbers::pi * grain_r * grain_r);
  const double overlap = grain_r - s.x[0].z();
  std::printf("wall: equilibrium overlap %.4g m, closed form %.4g m\n", overlap, expected);
  EXPECT_NEAR(overlap / expected, 1.0, 0.01);
}

TEST(ContactLawRegistry, ASceneNamingAnUnknownLawOrAnUncompiledCombinationIsRefusedNamingTheKey) {
  dem::State s;
  s.add_sphere(0, Vec3::Zero(), grain_r, 2500, 0);
  dem::ModelSpec unknown = pull_spec({test::glass()});
  unknown.law.cohesion = "glue";
  try {
    dem::compile_model(unknown, s, "scene.toml");
    ADD_FAILURE() << "an unknown law was accepted";
  } catch (const diefill::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("contact.cohesion"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("test_constant_pull"), std::string::npos) << e.what();  // the choices
  }
  dem::ModelSpec uncompiled = pull_spec({test::glass()});
  uncompiled.law.normal = "linear";
  uncompiled.linear_stiffness = 1e3;
  try {
    dem::compile_model(uncompiled, s, "scene.toml");
    ADD_FAILURE() << "an uncompiled combination was accepted";
  } catch (const diefill::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not compiled together"), std::string::npos) << e.what();
  }
}
