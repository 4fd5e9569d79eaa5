#pragma once
// Filling the shoe and letting the powder settle at rest at its start: grains inserted in rounds
// until the bed reaches shoe.fill_height (or the shoe is full, which is said), settled, and
// cached by everything that shapes the result, so that runs differing only in what happens
// afterwards reuse it.
#include <optional>
#include <string>

#include "dem/state.hpp"
#include "pipeline/walls.hpp"

namespace pipeline {

// What the cached settled shoe depends on besides the scene's settling keys (scene_keys.hpp).
struct SettledShoeInputs {
  std::string die_cache_key;
  GrainSizing grains;
  ShoePlan shoe;
  double table_z = 0;
  int powder = 0;
};
// The cache key: the settling keys' values, the materials, the derived geometry and the DEM's
// source hash (changed contact code never reuses a shoe settled by the old code).
std::string settled_shoe_key(const scene::PipelineScene& scene, const SettledShoeInputs& inputs, std::string_view dem_source_hash);

struct SettledShoe {
  dem::State state;            // at rest, time 0 (this rank's share of it, split over ranks)
  std::size_t requested = 0;   // grains for shoe.fill_height
  std::size_t inserted = 0;   // over every rank
  bool from_cache = false;
  double particle_steps = 0;  // grains × steps the settling took (0 from the cache): the plan's timings
};
// nullopt when Ctrl-C stopped the settling (nothing is cached then). Split over ranks (non-null
// `ranks`), the grains are settled split, and the state returned is this rank's share.
std::optional<SettledShoe> fill_and_settle_shoe(const scene::PipelineScene& scene, const FillWalls& walls, const GrainSizing& grains,
                                                const ShoePlan& shoe, double table_z, const std::shared_ptr<dem::Exchange>& ranks);

}  // namespace pipeline
