#pragma once
// The front end's commands, each a plain options struct and a function; main.cpp parses the
// command line (CLI11 stays in that one file) and maps exceptions to exit statuses.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bench/cases.hpp"

namespace cli {

std::string version_text();

struct SdfCommand {
  std::filesystem::path mesh;
  std::filesystem::path output;
  std::string units = "auto";
  std::string role = "cavity";
  std::string up = "auto";  // the way a cavity's opening faces in the file
  std::string parting = "auto";  // where the table meets a cavity's part (die.parting)
  int part = 0;                  // the body of an assembly's file (die.part); 0: all of it
  std::optional<double> voxel_mm;
  double grain_radius_mm = 0.5;
  double skin_mm = 0.25;
  std::optional<double> tolerance_mm;
  std::optional<double> max_hole_mm;
  double table_margin_mm = 10.0;
  std::size_t verify = 0;
  std::uint64_t seed = 1;
};
int run_sdf(const SdfCommand& command);

struct RunCommand {
  std::filesystem::path target;  // a die mesh, a folder of them, or a scene (.toml)
  std::filesystem::path out;     // overrides output.directory
  std::vector<std::string> overrides;
  std::optional<int> threads;
  std::optional<std::uint64_t> seed;
  std::optional<std::string> up;     // die.up
  std::optional<std::string> units;  // die.units
  bool resume = false;
  bool force = false;  // a size over the limit runs (pipeline/preflight.hpp)
  std::optional<int> seeds;              // > 1: a seed ensemble (pipeline/ensemble.hpp); per level of a ladder
  std::optional<std::string> ladder;     // A1,A2,A3: a grain-size ladder (pipeline/ladder.hpp)
  std::optional<double> extrapolate_to;  // the ladder's answer at this α (default 1: the real powder)
  std::optional<std::string> sweep;  // KEY=V1,V2,...: one run per value (pipeline/sweep.hpp)
  bool plan = false;                 // run what `diefill plan` chooses (pipeline/run_plan.hpp)
  double accuracy = 0.01;            // the plan's standard error of the fill ratio
  std::string budget = "30m";        // the plan's wall time
};
int run_pipeline(const RunCommand& command);

// `diefill plan TARGET`: the run's options and the cheapest that meets the accuracy in the budget.
struct PlanCommand {
  RunCommand run;                  // its target, --set, --threads, --out
  std::filesystem::path json;      // also write the plan here
};
int run_plan(const PlanCommand& command);

struct CompareCommand {
  std::filesystem::path run_a, run_b;
  std::filesystem::path out;  // required: a comparison never replaces another's folder unasked
};
int run_compare(const CompareCommand& command);

struct SceneCommand {
  std::filesystem::path target;
  std::vector<std::string> overrides;
  bool keys = false;  // the reference of every key (Markdown) instead of the resolved scene
  bool force = false;  // a size over the limit is printed, not refused
};
int run_scene(const SceneCommand& command);

struct SimulateCommand {
  std::filesystem::path scene;
  std::filesystem::path out;  // overrides output.directory
  std::vector<std::string> overrides;
  std::optional<int> threads;
  bool resume = false;
};
int run_simulate(const SimulateCommand& command);

struct BenchCommand {
  bench::Request request;
  std::filesystem::path json_out;
};
int run_bench(const BenchCommand& command);

struct DensityCommand {
  std::filesystem::path particles;  // CSV or VTU
  std::filesystem::path die;
  std::filesystem::path output;
  std::string units = "auto";  // as sdf and run read a die
  std::string role = "cavity";
  double voxel_mm = 0;        // 0: four grain radii
  std::string method = "exact";
  double width_mm = 0;        // Gaussian width (0: one voxel)
  double smoothed_width_mm = 0;  // the smoothed field's width (0: half the largest grain diameter)
  double material_density = 0;  // 0: from the particle file
  double coarse_graining = 1;    // α of the file's grains over the real powder's (1: they are the powder)
  bool fem = false;              // also the FEM hand-off (fem/)
  double element_size_mm = 0;    // 0: the voxel
  std::string elements = "linear";
};
int run_density(const DensityCommand& command);

struct DieCommand {
  std::string name;  // bundled die
  std::filesystem::path output;
};
int run_die(const DieCommand& command);

struct ClumpCommand {
  std::filesystem::path mesh;
  std::string units = "mm";
  double tolerance = 0.05;
  int max_spheres = 64;
  std::uint64_t seed = 1;
  std::filesystem::path output = "out/clumps";
};
int run_clump(const ClumpCommand& command);

// `diefill study`: studies/studies.hpp (studies::StudyRequest, studies::run_study).

}  // namespace cli
