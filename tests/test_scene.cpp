// Scene files: every key checked against its documented range at load time, naming the key;
// randomly mutated scenes load or are refused with InputError, never anything else; the settled
// shoe's cache key follows the keys that shape it and the DEM's code.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include "core/error.hpp"
#include "pipeline/census.hpp"
#include "pipeline/die_fill.hpp"
#include "pipeline/shoe_fill.hpp"
#include "scene/physics_keys.hpp"
#include "scene/pipeline_scene.hpp"
#include "support.hpp"

namespace {

// Loads a scene (default: the defaults) with its overrides; returns the InputError's text, or ""
// when it loads.
std::string refusal_of(const std::optional<std::filesystem::path>& scene, const std::vector<std::string>& overrides) {
  try {
    scene::load_pipeline_scene(scene, overrides);
    return "";
  } catch (const diefill::InputError& e) {
    return e.what();
  }
}
std::string refusal(const std::string& override_text) { return refusal_of(std::nullopt, {override_text}); }

// A value just outside a range, below or above (a whole number for an integer key); for a range
// that allows 0 besides its interval, the gap between them and a negative value too.
std::vector<double> outside(const scene::ValueRange& r, scene::KeyType type) {
  if (type == scene::KeyType::integer) return {r.lo - 1, r.hi + 1};
  const double below = r.lo_open ? r.lo : r.lo - std::max(1.0, std::abs(r.lo)) * 1e-3;
  const double above = r.hi_open ? r.hi : r.hi + std::max(1.0, std::abs(r.hi)) * 1e-3;
  if (r.or_zero) return {0.5 * r.lo, -r.lo, above};
  return {below, above};
}

std::string toml_number(double x, scene::KeyType type) {
  return type == scene::KeyType::integer ? fmt::format("{}", std::llround(x)) : fmt::format("{:e}", x);
}

}  // namespace

TEST(SceneKeys, EveryNumberOutsideItsRangeIsRefusedNamingTheKey) {
  int checked = 0;
  for (const auto& key : scene::pipeline_keys()) {
    if (key.type != scene::KeyType::number && key.type != scene::KeyType::integer && key.type != scene::KeyType::number_or_auto &&
        key.type != scene::KeyType::vec3)
      continue;
    for (double x : outside(key.range, key.type)) {
      const std::string value = key.type == scene::KeyType::vec3 ? fmt::format("[0, 0, {:e}]", x) : toml_number(x, key.type);
      const std::string why = refusal(key.path() + "=" + value);
      EXPECT_NE(why.find(key.path()), std::string::npos) << key.path() << " = " << value << ": " << why;
      ++checked;
    }
    EXPECT_FALSE(key.meaning.empty()) << key.path() << " is undocumented";
  }
  for (const auto& key : scene::material_keys()) {
    if (key.type != scene::KeyType::number) continue;
    for (double x : outside(key.range, key.type)) {
      // Materials are an array of tables: a scene file gives them.
      test::TempDir dir;
      test::write_text(dir / "scene.toml", fmt::format("[[materials]]\nname = \"powder\"\n{} = {:e}\n\n[[materials]]\nname = \"steel\"\n",
                                                      key.name, x));
      try {
        scene::load_pipeline_scene(dir / "scene.toml", {});
        ADD_FAILURE() << key.name << " = " << x << " loaded";
      } catch (const diefill::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("materials[0]." + std::string(key.name)), std::string::npos) << e.what();
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 60);
}

// The values the reviews found loading without a word, or refused under the wrong name: each
// key's lowest meaningful value is its bound (issue 44: 1e-300 ran the whole DEM, or for ever).
TEST(SceneKeys, AbsurdValuesFoundByTheReviewAreRefusedByName) {
  for (const char* key : {"powder.particle_diameter", "motion.speed", "motion.acceleration", "density.voxel",
                          "density.smoothed_width", "fem.element_size", "simulation.time_step", "die.voxel_fraction",
                          "output.fill_curve_every", "output.snapshot_every", "simulation.skin", "motion.die_settle_time"})
    EXPECT_NE(refusal(std::string(key) + "=1e-300").find(key), std::string::npos) << key;
  test::TempDir dir;
  for (const char* line : {"rolling_friction = 1e308", "density = 1e-300", "youngs_modulus = -1"}) {
    test::write_text(dir / "scene.toml", fmt::format("[[materials]]\nname = \"powder\"\n{}\n\n[[materials]]\nname = \"steel\"\n", line));
    const test::Run run = test::run_diefill("scene " + (dir / "scene.toml").string());
    EXPECT_EQ(run.status, 2) << line << ": " << run.output;
    EXPECT_NE(run.output.find(std::string(line).substr(0, std::string(line).find(' '))), std::string::npos) << run.output;
  }
}

// A scene states what differs: an entry named like a default material changes only the keys it
// gives (issue 48); the other material and the other keys keep their defaults.
TEST(SceneMaterials, AnEntryNamedLikeADefaultChangesOnlyItsKeys) {
  test::TempDir dir;
  test::write_text(dir / "scene.toml", "[[materials]]\nname = \"powder\"\nrolling_friction = 0.2\n");
  const scene::PipelineScene defaults;
  const scene::PipelineScene s = scene::load_pipeline_scene(dir / "scene.toml", {});
  ASSERT_EQ(s.spec.materials.size(), defaults.spec.materials.size());
  const dem::Material& powder = s.spec.materials[std::size_t(scene::material_named(s.spec, "powder"))];
  const dem::Material& default_powder = defaults.spec.materials[std::size_t(scene::material_named(defaults.spec, "powder"))];
  EXPECT_EQ(powder.rolling_friction, 0.2);
  EXPECT_EQ(powder.sliding_friction, default_powder.sliding_friction);
  EXPECT_EQ(powder.density, default_powder.density);
  EXPECT_EQ(s.spec.materials[std::size_t(scene::material_named(s.spec, "steel"))].youngs_modulus,
            defaults.spec.materials[std::size_t(scene::material_named(defaults.spec, "steel"))].youngs_modulus);

  const test::Run shown = test::run_diefill("scene " + (dir / "scene.toml").string());
  ASSERT_EQ(shown.status, 0) << shown.output;
  EXPECT_NE(shown.output.find("name = \"steel\""), std::string::npos) << shown.output;
  EXPECT_NE(shown.output.find("rolling_friction = 0.2"), std::string::npos) << shown.output;

  // A new name adds a material; the same name twice is refused, naming the entry.
  test::write_text(dir / "scene.toml", "[[materials]]\nname = \"brass\"\ndensity = 8500\n");
  EXPECT_EQ(scene::load_pipeline_scene(dir / "scene.toml", {}).spec.materials.size(), defaults.spec.materials.size() + 1);
  test::write_text(dir / "scene.toml", "[[materials]]\nname = \"powder\"\n\n[[materials]]\nname = \"powder\"\n");
  EXPECT_NE(refusal_of(dir / "scene.toml", {}).find("materials[1].name"), std::string::npos);
}

namespace {

// Random mutations of the fully resolved default scene: one to three lines each given a value
// from a list of troublemakers, or cut short.
std::vector<std::string> mutated_scenes(int count, std::uint64_t seed) {
  const std::string base = scene::describe(scene::PipelineScene{});
  std::vector<std::string> lines;
  std::stringstream in(base);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  const std::vector<std::string> values = {"-1",  "0",   "1e308", "-1e308", "1e-300", "nan", "inf",  "-inf", "\"text\"",
                                           "[1, 2, 3]", "true", "9223372036854775807", "{ a = 1 }", "\"auto\"", "3", "0.5"};
  std::mt19937_64 random(seed);
  std::vector<std::string> scenes;
  for (int n = 0; n < count; ++n) {
    std::vector<std::string> mutated = lines;
    for (int m = 0; m < 1 + int(random() % 3); ++m) {
      std::string& line = mutated[random() % mutated.size()];
      const std::size_t eq = line.find(" = ");
      if (random() % 5 == 0) line = line.substr(0, line.size() / 2);  // cut a line short
      else if (eq != std::string::npos) line = line.substr(0, eq) + " = " + values[random() % values.size()];
    }
    std::string text;
    for (const std::string& line : mutated) text += line + "\n";
    scenes.push_back(text);
  }
  return scenes;
}

}  // namespace

// A few hundred mutated scenes: each loads (and then every value lies in its range) or is refused
// with InputError; nothing else may escape.
TEST(SceneKeys, MutatedScenesLoadOrAreRefusedClearly) {
  test::TempDir dir;
  int loaded = 0, refused = 0;
  for (const std::string& text : mutated_scenes(300, 2026)) {
    test::write_text(dir / "scene.toml", text);
    try {
      const scene::PipelineScene s = scene::load_pipeline_scene(dir / "scene.toml", {});
      for (const auto& key : scene::pipeline_keys()) {
        if (key.type == scene::KeyType::number || key.type == scene::KeyType::integer) {
          EXPECT_TRUE(key.range.contains(std::get<double>(key.get(s)))) << key.path() << " in\n" << text;
        }
      }
      ++loaded;
    } catch (const diefill::InputError&) {
      ++refused;
    }
  }
  std::printf("mutated scenes: %d loaded, %d refused\n", loaded, refused);
  EXPECT_GT(refused, 100);
  EXPECT_GT(loaded, 10);
}

// Past loading (issue 44): every mutated scene that loads runs on the disc as a smoke run (every
// DEM stage cut at 30 steps, at most 400 grains: coarse, as its keys allow) and completes or
// stops with InputError or StabilityError, which `diefill` turns into exit status 2 or 3 with the
// message; never another exception, a crash or a hang (and, in the sanitizer stage, no undefined
// behaviour). The run's checks before its first step are those of `diefill scene`.
TEST(SceneKeys, MutatedScenesThatLoadRunOrStopClearly) {
  test::TempDir dir;
  int completed = 0, refused = 0, stopped = 0;
  for (const std::string& text : mutated_scenes(100, 44)) {
    test::write_text(dir / "scene.toml", text);
    scene::PipelineScene s;
    try {
      s = scene::load_pipeline_scene(dir / "scene.toml", {});
    } catch (const diefill::InputError&) {
      continue;
    }
    s.die.file = test::source_dir() / "dies" / "disc.stl";
    s.output.directory = dir / "out";
    s.output.cache = dir / "cache";
    s.max_steps = 30;
    s.powder.max_grains = std::min<std::size_t>(s.powder.max_grains, 400);
    s.fem.compaction = scene::FemCompaction::none;
    s.pictures = false;
    try {
      const pipeline::DieRun run = pipeline::run_die_fill(s, s.die.file, false);
      EXPECT_FALSE(run.interrupted);
      ++completed;
    } catch (const diefill::InputError&) {
      ++refused;
    } catch (const diefill::StabilityError&) {
      ++stopped;
    }
  }
  std::printf("mutated scenes run: %d completed, %d refused, %d stopped\n", completed, refused, stopped);
  EXPECT_GT(completed, 5);
}

// The settled shoe is reused only while everything that shaped it is unchanged: the settling
// keys and the DEM's code; the shoe's motion after settling does not count.
TEST(SettledShoe, KeyFollowsTheSettlingKeysAndTheDemCode) {
  const scene::PipelineScene scene;
  const pipeline::SettledShoeInputs inputs{"die", {0.8e-3, 0.44e-3, 8, 1000}, {}, 0, 0};
  const std::string key = pipeline::settled_shoe_key(scene, inputs, "dem-code-a");
  EXPECT_EQ(pipeline::settled_shoe_key(scene, inputs, "dem-code-a"), key);
  EXPECT_NE(pipeline::settled_shoe_key(scene, inputs, "dem-code-b"), key) << "changed DEM sources";
  scene::PipelineScene other = scene;
  other.motion.shoe_settle_time *= 1.5;
  EXPECT_NE(pipeline::settled_shoe_key(other, inputs, "dem-code-a"), key) << "a settling key";
  other = scene;
  other.spec.materials[0].sliding_friction = 0.45;
  EXPECT_NE(pipeline::settled_shoe_key(other, inputs, "dem-code-a"), key) << "a material";
  other = scene;
  other.motion.speed = 0.3;
  other.motion.die_settle_time = 0.2;
  other.density.voxel = 1e-3;
  other.threads = 2;
  EXPECT_EQ(pipeline::settled_shoe_key(other, inputs, "dem-code-a"), key) << "keys that act after the shoe has settled";
}

// A length key takes metres or a length with its unit, from --set as from a file; a unit it does
// not know is refused naming the key.
TEST(SceneKeys, ALengthKeyTakesItsUnit) {
  const scene::PipelineScene metres = scene::load_pipeline_scene(std::nullopt, {"shoe.length=0.04"});
  // 40 x 1e-3 is the double nearest 0.04 or its neighbour: the unit's factor is one rounding.
  EXPECT_DOUBLE_EQ(scene::load_pipeline_scene(std::nullopt, {"shoe.length=40mm"}).shoe.length, metres.shoe.length);
  EXPECT_DOUBLE_EQ(scene::load_pipeline_scene(std::nullopt, {"shoe.length=\"40 mm\""}).shoe.length, metres.shoe.length);
  EXPECT_EQ(scene::load_pipeline_scene(std::nullopt, {"simulation.skin=50um"}).spec.skin.value_or(0), 50 * 1e-6);
  try {
    scene::load_pipeline_scene(std::nullopt, {"shoe.length=40furlongs"});
    ADD_FAILURE() << "an unknown unit was accepted";
  } catch (const diefill::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("length"), std::string::npos) << e.what();
  }
}

// docs/INTERFACE.md's key reference is the table's own, so the two cannot drift apart.
TEST(SceneKeys, InterfaceDocumentListsEveryKeyAsTheTableHasIt) {
  const std::string doc = test::read_text(test::source_dir() / "docs" / "INTERFACE.md");
  const std::string begin = "<!-- generated by `diefill scene --keys`; tests/test_scene.cpp checks it is current -->\n";
  const std::size_t from = doc.find(begin), to = doc.find("<!-- end of generated keys -->");
  ASSERT_NE(from, std::string::npos);
  ASSERT_NE(to, std::string::npos);
  EXPECT_EQ(doc.substr(from + begin.size(), to - from - begin.size()), scene::scene_keys_markdown())
      << "regenerate the section with `diefill scene --keys`";
}

// The census sorts frozen grains by where they left the domain: beside it over the table's edge
// (spilled: physical), through the top (lost: a fault); and a grain the final state no longer
// holds is lost too, so that stability.checks can fail (issue 44).
TEST(Census, SortsGrainsThatLeftByTheFaceTheyCrossedAndCountsTheMissing) {
  dem::State s;
  const auto add = [&](const dem::Vec3& x, bool active) {
    s.add_sphere(std::int64_t(s.size()), x, 0.5e-3, 7800, 0);
    s.active.back() = active ? 1 : 0;
  };
  add(dem::Vec3(0, 0, -2e-3), true);        // in the cavity
  add(dem::Vec3(0, 0, 3e-3), true);         // in the shoe
  add(dem::Vec3(30e-3, 0, 1e-3), true);     // on the table beside the shoe
  add(dem::Vec3(0, 51e-3, 1e-3), false);    // over the table's side
  add(dem::Vec3(-51e-3, 0, 1e-3), false);   // over its end
  add(dem::Vec3(0, 0, 41e-3), false);       // out through the top
  pipeline::ShoePlan shoe;
  shoe.length = 20e-3, shoe.width = 20e-3;
  const dem::Box3 domain{dem::Vec3(-50e-3, -50e-3, -20e-3), dem::Vec3(50e-3, 50e-3, 40e-3)};
  const pipeline::Census c = pipeline::count_grains(s, 7, 0.0, shoe, domain);  // one inserted grain is missing
  EXPECT_EQ(c.inserted, 7u);
  EXPECT_EQ(c.grains, 6u);
  EXPECT_EQ(c.in_cavity, 1u);
  EXPECT_EQ(c.in_shoe, 1u);
  EXPECT_EQ(c.elsewhere, 1u);
  EXPECT_EQ(c.spilled, 2u);
  EXPECT_EQ(c.lost, 2u);
  EXPECT_EQ(c.leaked, 0u);
}
