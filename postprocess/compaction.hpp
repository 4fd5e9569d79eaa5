#pragma once
// The worked compaction example of the FEM hand-off (docs/INTERFACE.md, "FEM hand-off"): the
// filled cavity pressed by a rigid top punch in CalculiX, with a stiffness that depends on the
// fill's solid fraction. CalculiX has no cap-plasticity model: this is linear elasticity with
// Young's modulus tabulated against the solid fraction (carried as the nodes' temperature), enough
// to show how the fill's density reaches the FEM and to check the round trip against analytic
// solutions; a real compaction model (Drucker-Prager Cap) reads the same files in Abaqus.
#include <filesystem>
#include <vector>

#include "postprocess/fem.hpp"

namespace post {

struct CompactionSettings {
  double axial_strain = 0.01;             // the punch's travel over the cavity's depth
  double solid_youngs_modulus = 2.0e11;   // [Pa] at solid fraction 1 (steel)
  double modulus_exponent = 3.0;          // E(φ) = E_solid φ^n, tabulated every 0.05 of φ
  double poisson_ratio = 0.3;
};

// Young's modulus as the deck tabulates it and CalculiX interpolates it (linearly) [Pa].
double tabulated_modulus(const CompactionSettings& s, double solid_fraction);
// The constrained (oedometric) modulus E (1 - ν) / ((1 + ν)(1 - 2ν)): stress over strain in
// uniaxial strain [Pa].
double constrained_modulus(double youngs_modulus, double poisson_ratio);

struct CompactionResult {
  double punch_force_n = 0;                    // the table nodes' reaction along z (compressive > 0)
  double punch_travel_m = 0;
  std::vector<double> element_axial_stress;    // [Pa] σ_zz, mean over the integration points (compressive < 0)
  std::vector<Vec3> node_displacement;         // [m], in fill.inp's node order
  std::string log;                             // CalculiX' output
};

// Writes compaction.inp into `dir` (beside fill.inp and fill_calculix.inp of `fill`), runs ccx
// there and reads compaction.dat back. The punch moves the TABLE nodes down by the strain times
// the depth; FLOOR nodes are held along z; every boundary node is held in x and y (walls without
// slip: uniaxial strain). Throws InputError when ccx is missing or fails (its log named).
CompactionResult run_compaction(const FemFill& fill, const std::filesystem::path& dir, const CompactionSettings& s);

}  // namespace post
