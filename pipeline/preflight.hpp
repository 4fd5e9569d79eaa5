#pragma once
// What a run needs and will take, known before its first wall or grain exists: every check the
// DEM model's compilation makes, run on stand-in grains, and the run's size (docs/INTERFACE.md,
// `diefill scene`). `diefill scene` prints it; a run refuses a size too large to be meant.
#include <optional>
#include <string>

#include "dem/model.hpp"
#include "pipeline/plan.hpp"

namespace pipeline {

// The fill's coarse-grained laws, their impact speed raised to that of a grain falling the die's
// depth plus the shoe's speed: the collision time must resolve the fastest impact.
dem::ModelSpec fill_laws(const scene::PipelineScene& scene, const GrainSizing& grains, double die_depth);

struct RunSize {
  std::size_t grains = 0;                // that fill the shoe (clumps: times their spheres in the DEM)
  double settling_dt_s = 0, pass_dt_s = 0;
  std::size_t settling_steps = 0;        // per insertion round (none when the settled shoe is cached)
  std::size_t pass_steps = 0;            // the shoe's passes and the die's settling
  double particle_steps = 0;             // grains × (pass steps + every insertion round's settling): at most
};

// A run of more particle-steps is refused unless forced: 10³ times the default ring run's at most
// (16 042 grains × (79 955 + 4 × 9 692) steps = 1.9·10⁹, about two minutes on two cores).
inline constexpr double particle_step_limit = 2e12;
// The most voxels an output grid may hold: each takes a few tens of bytes over the stages.
inline constexpr double voxel_limit = 2e8;

// Compiles the settling's and the pass's models on stand-in grains (the smallest and the
// largest), so that every check the run's compilation makes, the shoe's travel per step
// included, refuses the scene now (InputError), and returns the run's size.
RunSize preflight(const scene::PipelineScene& scene, const DieSource& die, const ShoePlan& shoe, const GrainSizing& grains);
// The same checks for a scene without a die: the laws on the scene's own grains.
void preflight_laws(const scene::PipelineScene& scene);
// InputError naming `source` when the size exceeds the limit and the scene is not forced.
void refuse_oversized(const scene::PipelineScene& scene, const RunSize& size, const std::string& source);
// The size as TOML comment lines, for `diefill scene`.
std::string describe_size(const RunSize& size, const std::string& die_name);

}  // namespace pipeline
