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

struct SimulationOutput {
  std::filesystem::path directory = "out/simulation";
  bool trajectory = false;
  double trajectory_every = 1e-3;  // [s]
  double snapshot_every = 0;       // [s]; 0: none
};

// A [[walls]] mesh as the scene names it: its distance field is built by the simulation
// (pipeline/simulation.cpp), so that loading a scene builds nothing heavy.
struct MeshWallEntry {
  std::string name;  // the table's path (walls[k]), for messages and as the wall's name
  std::filesystem::path file;
  std::string units, role;  // choices the loader checked: mm, m or in; cavity, tool or container
  int material = 0;
  std::optional<dem::Motion> motion;
};

struct SimulationScene {
  std::string source;
  dem::ModelSpec spec;
  dem::State state;
  double duration = 1e-3;  // [s]
  int threads = 0;         // 0: all cores
  std::uint64_t seed = 1;
  SimulationOutput output;
  std::vector<MeshWallEntry> mesh_walls;  // in the order of [[walls]]; spec.meshes is empty until they are built
};

SimulationScene load_simulation_scene(const std::filesystem::path& path, const std::vector<std::string>& overrides);

}  // namespace scene
