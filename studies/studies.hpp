#pragma once
// The studies of `diefill study NAME` (the seed study's calibration experiments), each writing
// its tables, NAME.json and charts through `out`. `reduced` runs the small version the test
// suite uses: fewer and coarser grains, fewer points, the same law checked.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "scene/pipeline_scene.hpp"
#include "studies/study_kit.hpp"

namespace studies {

// `diefill study NAME [SCENE]`, as the command line and the tests give it.
struct StudyRequest {
  std::string name;
  std::optional<std::filesystem::path> scene;  // the powder to study (default: the pipeline's)
  std::vector<std::string> overrides;
  std::filesystem::path out = "out/studies";
  bool reduced = false;  // the small version the tests run
  std::optional<int> threads;
  std::optional<std::uint64_t> seed;
};
// Runs the study into OUT/NAME/; returns the exit status (130 when interrupted: nothing written).
int run_study(const StudyRequest& request);
std::vector<std::string> study_names();

// Mass flow through a slot against its width (Beverloo slot law: C_s, k), and the mass a moving
// shoe delivers through a die opening into a bin against its speed (moving-container law,
// critical-velocity law: v_c, n).
void discharge(const scene::PipelineScene& scene, bool reduced, Output& out);

// Heap and outflow angles of repose against sliding and rolling friction, with the Zhou et al.
// correlation for comparison.
void repose(const scene::PipelineScene& scene, bool reduced, Output& out);

// Invariance under coarse graining: slot flow, outflow angle and the ring die's fill density at
// three grain sizes, with the boundary corrections (Beverloo k·αd, the wall layer).
void coarse_graining(const scene::PipelineScene& scene, bool reduced, Output& out);

// The ring die's density-field error against wall-clock time, sweeping grain size, stiffness,
// time step and wall voxels: the Pareto front and the best settings for three time budgets.
void speed_accuracy(const scene::PipelineScene& scene, bool reduced, Output& out);

// Rolling friction calibrated on the outflow angle predicts the slot flow, and the reverse; the
// scene's powder with another seed stands for the measured one.
void cross_validation(const scene::PipelineScene& scene, bool reduced, Output& out);

// `diefill calibrate` on a twin powder measured by its own tests at another grain size and seed:
// the frictions it recovers against the true ones (calibrate.hpp).
void calibration_round_trip(const scene::PipelineScene& scene, bool reduced, Output& out);

// Where each method fails (time step, wall voxels, shoe speed against the skin, grains too
// coarse for the cavity): each probed, and whether the stability checks caught it.
void stability(const scene::PipelineScene& scene, bool reduced, Output& out);

}  // namespace studies
