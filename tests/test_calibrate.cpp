// Your powder (issue 48): `diefill calibrate`, whose powder of known frictions is "measured" by
// the tool's own tests at another grain size and seed, written as a lab's file, and calibrated
// back; the measured file's errors, naming the file and the key; and the example scenes.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "pipeline/die_fill.hpp"
#include "scene/pipeline_scene.hpp"
#include "studies/calibrate.hpp"
#include "studies/studies.hpp"
#include "support.hpp"

namespace {

namespace fs = std::filesystem;
using studies::MeasuredPowder;

// A lab's file that reads, broken one key at a time below.
MeasuredPowder lab_powder() {
  MeasuredPowder m;
  m.source = "lab";
  m.particle_diameter = 1.2e-3;
  m.material_density = 7800;
  m.orifice_diameter = 14.4e-3;
  m.repose_deg = 30;
  m.apparent_density = 4500;
  m.flow_rate = 0.05;
  return m;
}

}  // namespace

// `diefill study calibration-round-trip`, reduced (each test once): a twin of known frictions,
// μ = 0.4 and μ_r = 0.12, measured at another grain size and seed and calibrated back. Asserted:
// each true friction lies inside the 95 % interval calibrate reports, and so does the combination
// of the two the measurements fix best; the block loads as a scene; a resumed calibration reruns
// nothing. Not asserted, because out of reach: the issue's ±0.05 on each (docs/STUDIES.md,
// "calibration-round-trip": the measurements move with nearly one combination of the two).
TEST(Calibrate, TheTrueFrictionsOfItsOwnTwinLieInsideTheReportedIntervals) {
  test::TempDir dir;
  studies::StudyRequest study;
  study.name = "calibration-round-trip";
  study.reduced = true;
  study.out = dir / "studies";
  ASSERT_EQ(studies::run_study(study), 0);
  std::ifstream in(study.out / study.name / (study.name + ".json"));
  const nlohmann::json r = nlohmann::json::parse(in);
  for (const char* name : {"sliding_friction", "rolling_friction"})
    EXPECT_LE(std::abs(r[name]["error"].get<double>()), r[name]["ci95"].get<double>()) << name << ": " << r.dump(1);
  for (const auto& o : r["observables"]) EXPECT_TRUE(o.contains("residual")) << o.dump();
  const nlohmann::json& best_fixed = r["fixed_combinations"][0];
  EXPECT_LE(std::abs(best_fixed["error"].get<double>()), best_fixed["measurements_ci95"].get<double>()) << best_fixed.dump();

  // The block is ready to use: a scene of it loads with the fitted values and keeps the steel.
  const fs::path runs = study.out / study.name / "runs";
  const scene::PipelineScene calibrated = scene::load_pipeline_scene(runs / "calibration" / "calibrated.toml", {});
  const dem::Material& powder = calibrated.spec.materials[std::size_t(scene::material_named(calibrated.spec, "powder"))];
  EXPECT_NEAR(powder.sliding_friction, r["sliding_friction"]["value"].get<double>(), 5e-4);
  EXPECT_NEAR(powder.rolling_friction, r["rolling_friction"]["value"].get<double>(), 5e-4);
  EXPECT_NO_THROW(scene::material_named(calibrated.spec, "steel"));

  // Resumed, the finished tests are kept: nothing runs again (the checkpoint does not grow) and
  // the result is the same.
  studies::CalibrateRequest c;
  c.measured = runs / "measured.toml";
  c.out = runs / "calibration";
  c.repeats = 1;
  c.resume = true;
  const auto tests_kept = fs::file_size(c.out / ".calibration_tests.jsonl");
  fs::remove(c.out / "calibration.json");
  ASSERT_EQ(studies::run_calibrate(c), 0);
  EXPECT_EQ(fs::file_size(c.out / ".calibration_tests.jsonl"), tests_kept);
  std::ifstream again(c.out / "calibration.json");
  EXPECT_EQ(nlohmann::json::parse(again)["sliding_friction"]["value"], r["sliding_friction"]["value"]);
}

TEST(Calibrate, MeasuredFileErrorsNameTheFileAndTheKey) {
  test::TempDir dir;
  const std::string good = studies::measured_powder_toml(lab_powder());
  ASSERT_NO_THROW(studies::read_measured_powder([&] {
    test::write_text(dir / "m.toml", good);
    return dir / "m.toml";
  }()));
  struct Break {
    std::string from, to, key;
  };
  const std::vector<Break> breaks = {
      {"apparent_density = 4500", "apparent_density = 9000", "powder.apparent_density"},  // above the material's density
      {"angle_deg = 30", "angle_deg = 95", "repose.angle_deg"},
      {"orifice_diameter = ", "orifice_diameter = 1e-3 #", "flow.orifice_diameter"},   // narrower than six grains
      {"[repose]", "[repose]\nangel_deg = 3", "angel_deg"},                             // a misspelt key
  };
  for (const Break& b : breaks) {
    std::string text = good;
    text.replace(text.find(b.from), b.from.size(), b.to);
    test::write_text(dir / "m.toml", text);
    const test::Run run = test::run_diefill("calibrate " + (dir / "m.toml").string() + " -o " + (dir / "out").string());
    EXPECT_EQ(run.status, 2) << b.to << ": " << run.output;
    EXPECT_NE(run.output.find("m.toml"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find(b.key), std::string::npos) << b.key << ": " << run.output;
  }
  EXPECT_FALSE(fs::exists(dir / "out" / "calibrated.toml"));
}

// Each example (examples/*.toml) loads as `diefill scene` shows it; each scene runs coarsely (a
// smoke run: at most 3000 grains, 30 steps a DEM stage, no FEM), the measured powder loads.
TEST(Examples, EachLoadsAndEachSceneRunsCoarsely) {
  int scenes = 0, measured = 0;
  for (const auto& entry : fs::directory_iterator(test::source_dir() / "examples")) {
    if (entry.path().extension() != ".toml") continue;
    const test::Run shown = test::run_diefill("scene " + entry.path().string());
    EXPECT_EQ(shown.status, 0) << entry.path() << ": " << shown.output;
    if (studies::is_measured_powder(entry.path())) {
      ++measured;
      continue;
    }
    test::TempDir dir;
    scene::PipelineScene s = scene::load_pipeline_scene(entry.path(), {});
    s.output.directory = dir / "out";
    s.output.cache = dir / "cache";
    s.max_steps = 30;
    s.powder.max_grains = std::min<std::size_t>(s.powder.max_grains, 3000);
    s.fem.elements = scene::FemElements::none;
    s.pictures = false;
    EXPECT_NO_THROW(EXPECT_FALSE(pipeline::run_die_fill(s, s.die.file, false).interrupted)) << entry.path();
    ++scenes;
  }
  EXPECT_GE(scenes, 4);
  EXPECT_GE(measured, 1);
}
