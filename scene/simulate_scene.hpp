#pragma once
// The scene of `diefill simulate` (docs/INTERFACE.md): explicit particles, materials, contact laws,
// plane and mesh walls with motions, output settings. Its keys, with their ranges, are tables of
// scene_keys.hpp like the pipeline's.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "dem/model.hpp"
#include "dem/state.hpp"

namespace scene {

struct OutputSettings {
  std::filesystem::path directory = "out/simulation";
  bool trajectory = false;
  double trajectory_every = 1e-3;  // [s]
  double snapshot_every = 0;       // [s]; 0: none
};

struct SimulationScene {
  std::string source;
  dem::ModelSpec spec;
  dem::State state;
  double duration = 1e-3;  // [s]
  int threads = 0;         // 0: all cores
  std::uint64_t seed = 1;
  OutputSettings output;
};

SimulationScene load_simulation_scene(const std::filesystem::path& path, const std::vector<std::string>& overrides);

}  // namespace scene
