// diefill's command line. Parsing only: each command lives in its own file (commands.hpp).
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <malloc.h>

#include "cli/commands.hpp"
#include "cli/mpi_session.hpp"
#include "studies/calibrate.hpp"
#include "studies/studies.hpp"
#include "core/error.hpp"
#include "core/length.hpp"
#include "core/log.hpp"

namespace {

// A length flag: a bare number is millimetres, as its help says; a number with its unit is
// converted (core/length.hpp; docs/INTERFACE.md, "Lengths").
CLI::Option* in_mm(CLI::Option* option) {
  return option->transform(CLI::Validator(
      [](std::string& text) {
        if (const std::optional<diefill::Length> length = diefill::parse_length(text)) text = fmt::format("{}", length->millimetres());
        else if (!diefill::parse_length(text + "mm"))
          return "\"" + text + "\" is not a length: give millimetres, or a number with its unit (0.2mm, 2e-4m, 200um, 0.01in)";
        return std::string();
      },
      "", "length"));
}

void add_sdf(CLI::App& root, cli::SdfCommand& c, std::function<int()>& action) {
  CLI::App* cmd = root.add_subcommand("sdf", "Check and repair a mesh, then write its signed-distance grid");
  cmd->add_option("MESH", c.mesh, "Mesh file (STL, OBJ, PLY, OFF, ...)")->required();
  cmd->add_option("-o,--out", c.output, "Output .vdb file");
  in_mm(cmd->add_option("--voxel", c.voxel_mm, "Voxel edge [mm] (default: a quarter of the grain radius)"));
  cmd->add_option("--units", c.units, "Length unit of the file: mm, m, in, or auto (guessed from its size)")
      ->capture_default_str();
  cmd->add_option("--up", c.up, "The way a cavity's opening faces in the file: +x, -x, +y, -y, +z, -z, or auto (found)")
      ->capture_default_str();
  cmd->add_option("--parting", c.parting,
                  "Where the table meets a cavity's part: opening (its flat face), widest (its widest section) or auto "
                  "(die.parting)")
      ->capture_default_str();
  cmd->add_option("--part", c.part,
                  "For an assembly's file: the body the die is for, numbered by volume, largest first; 0: the whole file "
                  "(die.part)")
      ->capture_default_str();
  cmd->add_option("--role", c.role, "cavity (the part, open at the table), tool (the die body) or container (a closed vessel)")
      ->capture_default_str();
  in_mm(cmd->add_option("--grain-radius", c.grain_radius_mm, "Largest grain radius [mm]"))->capture_default_str();
  in_mm(cmd->add_option("--skin", c.skin_mm, "Neighbour skin [mm]"))->capture_default_str();
  in_mm(cmd->add_option("--tolerance", c.tolerance_mm, "Largest change repair may make [mm] (default: half a voxel)"));
  in_mm(cmd->add_option("--max-hole", c.max_hole_mm, "Largest hole repair fills [mm] (default: 10 voxels)"));
  in_mm(cmd->add_option("--table-margin", c.table_margin_mm, "Die table beyond the cavity [mm]"))->capture_default_str();
  cmd->add_option("--verify", c.verify, "Compare N points in the band with the exact distance");
  cmd->add_option("--seed", c.seed, "Seed of the verification points")->capture_default_str();
  cmd->callback([&] { action = [&] { return cli::run_sdf(c); }; });
}

void add_run(CLI::App& root, cli::RunCommand& c, std::function<int()>& action) {
  CLI::App* cmd = root.add_subcommand("run", "The whole pipeline on a die mesh, a folder of meshes, or a scene");
  cmd->add_option("TARGET", c.target, "Die mesh, folder of meshes, or scene (.toml)")->required();
  cmd->add_option("-o,--out", c.out, "Output folder; each die writes into OUT/<die name>/ (default out)");
  cmd->add_option("--set", c.overrides, "Override a scene key: --set motion.speed=0.2");
  cmd->add_option("--threads", c.threads, "Threads (default: all cores); results do not depend on it");
  cmd->add_option("--seed", c.seed, "Random seed of the powder");
  cmd->add_option("--up", c.up, "The way the die's opening faces in its file: +x, -x, +y, -y, +z, -z or auto (die.up)");
  cmd->add_option("--units", c.units, "Length unit of the die's file: mm, m, in, or auto (die.units)");
  cmd->add_flag("--resume", c.resume, "Continue an interrupted run from its checkpoint");
  cmd->add_flag("--force", c.force, "Run a scene whose size is over the limit (10³ times the default ring run's work)");
  cmd->add_option("--seeds", c.seeds,
                  "Run N seeds (from --seed or simulation.seed on), each into OUT/simulation.seed=K/, and their mean with "
                  "its standard error into OUT/<die name>/ (with --ladder: seeds per level, default 2)");
  cmd->add_option("--ladder", c.ladder,
                  "Run the scene at three or more coarse-graining levels (A1,A2,A3), each a seed ensemble, and extrapolate "
                  "the fill to the powder's real size");
  cmd->add_option("--extrapolate-to", c.extrapolate_to, "With --ladder: the coarse graining to extrapolate to (default 1)");
  cmd->add_flag("--plan", c.plan, "Run what `diefill plan` chooses for --accuracy within --budget");
  cmd->add_option("--accuracy", c.accuracy, "With --plan: the standard error of the fill ratio asked for")->capture_default_str();
  cmd->add_option("--budget", c.budget, "With --plan: the wall time allowed (90s, 30m, 2h, 1h30m)")->capture_default_str();
  cmd->add_option("--sweep", c.sweep,
                  "Run once per value of a scene key, each into OUT/KEY=VALUE/, with a summary table and chart: "
                  "--sweep motion.speed=0.05,0.1,0.2");
  cmd->callback([&] { action = [&] { return cli::run_pipeline(c); }; });
}

void add_plan(CLI::App& root, cli::PlanCommand& c, std::function<int()>& action) {
  CLI::App* cmd = root.add_subcommand("plan", "What each grain size would take and miss by, and the cheapest way to an accuracy");
  cmd->add_option("TARGET", c.run.target, "Die mesh or scene (.toml)")->required();
  cmd->add_option("--set", c.run.overrides, "Override a scene key");
  cmd->add_option("--accuracy", c.run.accuracy, "The standard error of the fill ratio asked for")->capture_default_str();
  cmd->add_option("--budget", c.run.budget, "The wall time allowed on this machine (90s, 30m, 2h, 1h30m)")->capture_default_str();
  cmd->add_option("--threads", c.run.threads, "Threads the runs would take (default: all cores)");
  cmd->add_option("-o,--out", c.run.out, "Where the runs would write (its .cache holds this machine's timings)");
  cmd->add_option("--json", c.json, "Also write the plan as JSON to this file");
  cmd->callback([&] { action = [&] { return cli::run_plan(c); }; });
}

void add_scene(CLI::App& root, cli::SceneCommand& c, std::function<int()>& action) {
  CLI::App* cmd = root.add_subcommand("scene", "Print the fully resolved scene (every default, with its reason)");
  cmd->add_option("TARGET", c.target, "Die mesh or scene (.toml)");
  cmd->add_option("--set", c.overrides, "Override a scene key");
  cmd->add_flag("--keys", c.keys, "Print every key with its type, unit, default, range and meaning (Markdown)");
  cmd->add_flag("--force", c.force, "Accept a size over the limit, as `run --force` would");
  cmd->callback([&] { action = [&] { return cli::run_scene(c); }; });
}

void add_simulate(CLI::App& root, cli::SimulateCommand& c, std::function<int()>& action) {
  CLI::App* cmd = root.add_subcommand("simulate", "Run a general DEM scene (explicit particles, walls, motions)");
  cmd->add_option("SCENE", c.scene, "Scene file (TOML)")->required();
  cmd->add_option("-o,--out", c.out, "Output folder (overrides output.directory)");
  cmd->add_option("--set", c.overrides, "Override a scene key: --set simulation.duration=0.01");
  cmd->add_option("--threads", c.threads, "Threads (default: all cores)");
  cmd->add_flag("--resume", c.resume, "Continue from the output folder's checkpoint");
  cmd->callback([&] { action = [&] { return cli::run_simulate(c); }; });
}

void add_bench(CLI::App& root, cli::BenchCommand& c, std::function<int()>& action) {
  CLI::App* cmd = root.add_subcommand("bench", "Performance cases; JSON results");
  cmd->add_option("CASE", c.request.cases, "ring-10k, ring-100k (default both), liggghts, scaling (tiles of the LIGGGHTS pack, 5k to 500k grains), run-ring (the default pipeline on the ring, end to end), mpi-bed (under mpirun: a bed of --grains split over the ranks, stepped to step --steps)");
  cmd->add_option("--json", c.json_out, "Write the results here instead of standard output");
  cmd->add_option("--threads", c.request.threads, "Thread counts to time (default 1 2)");
  cmd->add_option("--steps", c.request.steps, "Timed steps per run")->capture_default_str();
  cmd->add_option("--cache", c.request.cache, "Folder for prepared packs and SDFs")->capture_default_str();
  cmd->add_option("--pack", c.request.pack, "liggghts: settled pack (LAMMPS dump: id x y z radius vx vy vz)");
  cmd->add_option("--stl", c.request.stl, "liggghts: container mesh (mm)");
  cmd->add_option("--sizes", c.request.sizes, "scaling: grain counts")->capture_default_str();
  cmd->add_flag("--unsettled-beds", c.request.unsettled_beds,
                "scaling: time beds of several tiles as laid out, not settled again (for bytes per grain and the rebuild's time; their rates are not like for like)");
  cmd->add_option("--grains", c.request.grains, "mpi-bed: grains in the bed")->capture_default_str();
  cmd->add_option("--checkpoint-at", c.request.checkpoint_at, "mpi-bed: write a checkpoint (CACHE/mpi-bed/checkpoint.bin) at this step");
  cmd->add_option("--resume", c.request.resume, "mpi-bed: go on from this checkpoint to --steps");
  cmd->callback([&] { action = [&] { return cli::run_bench(c); }; });
}

void add_density(CLI::App& root, cli::DensityCommand& c, std::function<int()>& action) {
  CLI::App* cmd = root.add_subcommand("density", "Density field of a particle file on a die");
  cmd->add_option("PARTICLES", c.particles, "Particles CSV or VTU snapshot")->required();
  cmd->add_option("--die", c.die, "The die's cavity mesh")->required();
  cmd->add_option("-o,--out", c.output, "Output folder")->required();
  cmd->add_option("--units", c.units, "Length unit of the die mesh: mm, m, in, or auto (guessed from its size)")
      ->capture_default_str();
  cmd->add_option("--role", c.role, "cavity or container")->capture_default_str();
  in_mm(cmd->add_option("--voxel", c.voxel_mm, "Voxel edge [mm] (default: four grain radii)"));
  cmd->add_option("--method", c.method, "exact (volume split exactly) or gaussian (kernel)")->capture_default_str();
  in_mm(cmd->add_option("--width", c.width_mm, "Gaussian width [mm] (default: one voxel)"));
  in_mm(cmd->add_option("--smoothed-width", c.smoothed_width_mm,
                  "Width [mm] of the smoothed field written beside the main one (Gaussian, on voxels as wide; default "
                  "half the largest grain diameter)"));
  cmd->add_option("--material-density", c.material_density, "Grain material density [kg/m³] (default: from the file)");
  cmd->add_option("--coarse-graining", c.coarse_graining,
                  "The file's grains over the real powder's size, recorded in the field (1: they are the powder)")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 1e4));
  cmd->add_flag("--fem", c.fem, "Also the FEM hand-off in OUTPUT/fem/: tetrahedral mesh with the fill per element (fill.inp, fill.vtu) "
                                "and the CalculiX compaction example");
  in_mm(cmd->add_option("--element-size", c.element_size_mm, "The tetrahedra's largest edge [mm] (default: the voxel)"));
  cmd->add_option("--elements", c.elements, "linear (C3D4) or quadratic (C3D10)")
      ->capture_default_str()
      ->check(CLI::IsMember({"linear", "quadratic"}));
  cmd->callback([&] { action = [&] { return cli::run_density(c); }; });
}

void add_compare(CLI::App& root, cli::CompareCommand& c, std::function<int()>& action) {
  CLI::App* cmd = root.add_subcommand("compare", "Two runs of one die side by side: fill statistics and the density difference");
  cmd->add_option("RUN_A", c.run_a, "A run's output folder (OUT/<die name>/)")->required();
  cmd->add_option("RUN_B", c.run_b, "The other run's folder; differences are B - A")->required();
  cmd->add_option("-o,--out", c.out, "Output folder: compare.json, difference.vdb, compare.png")->required();
  cmd->callback([&] { action = [&] { return cli::run_compare(c); }; });
}

void add_die(CLI::App& root, cli::DieCommand& c, std::function<int()>& action) {
  CLI::App* cmd = root.add_subcommand("die", "Write a bundled die mesh (ring, disc, gear, slot, spline) as binary STL in mm");
  cmd->add_option("NAME", c.name, "ring, disc, gear (24 teeth, module 1.2 mm), slot (1.2 mm wide) or spline (a splined bore, ISO 14 6 x 11 x 14)")->required();
  cmd->add_option("-o,--out", c.output, "Output STL")->required();
  cmd->callback([&] { action = [&] { return cli::run_die(c); }; });
}

void add_clump(CLI::App& root, cli::ClumpCommand& c, std::function<int()>& action) {
  CLI::App* cmd = root.add_subcommand("clump", "Build the multi-sphere template of a grain shape, with its errors against the sphere count");
  cmd->add_option("MESH", c.mesh, "Closed grain surface mesh")->required();
  cmd->add_option("--units", c.units, "Length unit of the file: mm, m or in")->capture_default_str();
  cmd->add_option("--tolerance", c.tolerance, "Largest volume and Hausdorff error, relative to the equivalent diameter")
      ->capture_default_str();
  cmd->add_option("--max-spheres", c.max_spheres, "Most spheres per grain")->capture_default_str();
  cmd->add_option("--seed", c.seed, "Seed of the surface sampling")->capture_default_str();
  cmd->add_option("-o,--out", c.output,
                  "The template file (ending in .json, with NAME_errors.csv and .png beside it), or a folder for NAME.json, ...")
      ->capture_default_str();
  cmd->callback([&] { action = [&] { return cli::run_clump(c); }; });
}

void add_study(CLI::App& root, studies::StudyRequest& c, std::function<int()>& action) {
  std::string names;
  for (const std::string& name : studies::study_names()) names += (names.empty() ? "" : ", ") + name;
  CLI::App* cmd = root.add_subcommand("study", "Calibration and method studies; CSV, JSON and PNG charts in OUT/NAME/");
  cmd->add_option("NAME", c.name, "Study: " + names)->required();
  cmd->add_option("SCENE", c.scene, "Scene (.toml) whose powder and contact laws are studied (default: the pipeline's)");
  cmd->add_option("--set", c.overrides, "Override a scene key: --set powder.coarse_graining=16");
  cmd->add_option("-o,--out", c.out, "Output folder")->capture_default_str();
  cmd->add_flag("--reduced", c.reduced, "The small version the tests run (coarser, fewer points; minutes)");
  cmd->add_option("--threads", c.threads, "Threads (default: all cores); results do not depend on it");
  cmd->add_option("--seed", c.seed, "Random seed of the powder");
  cmd->callback([&] { action = [&] { return studies::run_study(c); }; });
}

void add_calibrate(CLI::App& root, studies::CalibrateRequest& c, std::function<int()>& action) {
  CLI::App* cmd = root.add_subcommand("calibrate", "Fit sliding and rolling friction to a powder's lab measurements; a [[materials]] "
                                                   "block with its confidence in OUT/calibrated.toml");
  cmd->add_option("MEASURED", c.measured, "What the lab measured (.toml: docs/INTERFACE.md, \"The measured powder\")")->required();
  cmd->add_option("-o,--out", c.out, "Output folder")->capture_default_str();
  cmd->add_flag("--resume", c.resume, "Keep the tests an interrupted calibration finished");
  cmd->add_option("--repeats", c.repeats, "Seeds per design point: more narrow the intervals")
      ->capture_default_str()
      ->check(CLI::Range(1, 50));
  cmd->add_option("--set", c.overrides, "Override a scene key of the simulated powder: --set contact.rolling=epsd");
  cmd->add_option("--threads", c.threads, "Threads (default: all cores); results do not depend on it");
  cmd->add_option("--seed", c.seed, "Random seed of the simulated tests")->capture_default_str();
  cmd->callback([&] { action = [&] { return studies::run_calibrate(c); }; });
}

}  // namespace

int main(int argc, char** argv) {
  // Arrays of a megabyte and more come from the system and go back to it when freed. glibc's
  // default threshold rises to 32 MB after the first large free, after which the lists and
  // buffers of each neighbour rebuild are carved from the heap and stay resident: a rank of
  // millions of grains then held twice its arrays (bench/mpi_10m.sh: 1,439 against 742 bytes per
  // grain on 500,000 grains a rank).
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
  const cli::MpiSession mpi(argc, argv);
  CLI::App root{"diefill: simulate how a powder fills a press die"};
  root.set_version_flag("--version", [] { return cli::version_text(); });
  root.require_subcommand(1);
  root.footer("Lengths: a bare number is millimetres on the command line and metres in a scene; either takes a unit: "
              "0.2mm, 2e-4m, 200um, 0.01in.");
  bool verbose = false;
  root.add_flag("-v,--verbose", verbose, "Log each stage with its time");
  root.parse_complete_callback([&] {
    // Ranks after the first of a split run stay quiet (mpi_session.cpp), verbose or not.
    if (verbose && diefill::log::level() != diefill::log::Level::quiet) diefill::log::set_level(diefill::log::Level::verbose);
  });
  std::function<int()> action;
  cli::SdfCommand sdf;
  cli::DieCommand die;
  cli::RunCommand run;
  add_run(root, run, action);
  cli::SceneCommand scene;
  add_scene(root, scene, action);
  cli::PlanCommand plan;
  add_plan(root, plan, action);
  cli::SimulateCommand simulate;
  add_simulate(root, simulate, action);
  cli::BenchCommand bench;
  add_bench(root, bench, action);
  cli::DensityCommand density;
  add_density(root, density, action);
  add_sdf(root, sdf, action);
  add_die(root, die, action);
  cli::CompareCommand compare;
  add_compare(root, compare, action);
  cli::ClumpCommand clump;
  add_clump(root, clump, action);
  studies::StudyRequest study;
  add_study(root, study, action);
  studies::CalibrateRequest calibrate;
  add_calibrate(root, calibrate, action);
  try {
    root.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int status = root.exit(e);
    return status == 0 ? 0 : diefill::exit_bad_input;
  }
  const std::shared_ptr<dem::Exchange> ranks = cli::mpi_exchange();
  const bool split = ranks && ranks->ranks() > 1;
  if (split && !root.got_subcommand("run") && !root.got_subcommand("simulate") && !root.got_subcommand("bench")) {
    if (ranks->rank() == 0)
      fmt::print(stderr, "error: mpirun: only `diefill run`, `simulate` and `bench` are split over MPI ranks; run the other "
                         "commands without mpirun (they use every core through threads)\n");
    return diefill::exit_bad_input;
  }
  // Split over ranks, input and stability errors arise on every rank together (the ranks decide
  // them collectively): rank 0 says them. Any other error is one rank's, and the others would wait
  // for it forever: it stops them all.
  const bool says = !split || ranks->rank() == 0;
  try {
    return action ? action() : diefill::exit_ok;
  } catch (const diefill::InputError& e) {
    if (says) fmt::print(stderr, "error: {}\n", e.what());
    return diefill::exit_bad_input;
  } catch (const diefill::StabilityError& e) {
    if (says) fmt::print(stderr, "stopped: {}\n", e.what());
    return diefill::exit_unstable;
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    if (split) cli::abort_all_ranks(diefill::exit_other);
    return diefill::exit_other;
  }
}
