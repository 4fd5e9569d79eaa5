// The die-filling pipeline end to end on the bundled ring and disc, with 1.6 mm grains (coarse
// graining 16: about 2500 grains) so that a run takes seconds: every grain counted, the fill
// ratio against the shoe's speed, the ring's mirror symmetry, identical reports from the same
// seed, the settled shoe reused across speeds. The cases of suite `Pipeline` share their runs
// (the ring's and the disc's base fills) through `run`'s memo and run in one process; those of
// `PipelineOwnRuns` make their own and run each in its own, beside the others (tests/CMakeLists.txt).
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>

#include "pipeline/compare.hpp"
#include "pipeline/density_stage.hpp"
#include "pipeline/die_fill.hpp"
#include "pipeline/sweep.hpp"
#include "pipeline/throughput.hpp"
#include "core/error.hpp"
#include "scene/pipeline_scene.hpp"
#include "dem/io.hpp"
#include "mesh/die.hpp"
#include "mesh/import.hpp"
#include "mesh/shapes.hpp"
#include "postprocess/density.hpp"
#include "postprocess/field.hpp"
#include "clump_report.hpp"
#include "support.hpp"

namespace {

namespace fs = std::filesystem;

fs::path bundled_die(const std::string& name) { return fs::path(DIEFILL_SOURCE_DIR) / "dies" / (name + ".stl"); }

// One output folder for the whole suite, so that runs share the cached die and settled shoe.
fs::path suite_out() { return test::suite_folder("pipeline"); }

struct RunKey {
  std::string die;
  double speed;
  std::uint64_t seed;
  std::string folder;
  std::string grains;
  auto operator<=>(const RunKey&) const = default;
};

// 1.6 mm grains: the fastest size at which the ring's 5 mm gap still fills.
const std::string coarse = "powder.coarse_graining=16";

// Runs (once per key) and returns the report; the outputs go to suite_out()/folder/<die>.
const nlohmann::json& run(const std::string& die, double speed, std::uint64_t seed, const std::string& folder = "a",
                          const std::string& grains = coarse) {
  static std::map<RunKey, nlohmann::json> done;
  const RunKey key{die, speed, seed, folder, grains};
  if (auto it = done.find(key); it != done.end()) return it->second;
  std::vector<std::string> overrides = {fmt::format("motion.speed={}", speed), fmt::format("simulation.seed={}", seed),
                                        "output.directory=" + (suite_out() / folder).string()};
  std::stringstream list(grains);
  for (std::string item; std::getline(list, item, ' ');) overrides.push_back(item);
  // The FEM hand-off is tested on the plain runs; the variants leave it out (about 2 s each)
  // unless they ask for it.
  if (grains != coarse && grains.find("fem.elements") == std::string::npos) overrides.push_back("fem.elements=none");
  scene::PipelineScene scene = scene::load_pipeline_scene(std::nullopt, overrides);
  // Pictures are looked at on the plain runs only (python, a few seconds a run).
  scene.pictures = folder == "a" && grains == coarse;
  const pipeline::DieRun r = pipeline::run_die_fill(scene, bundled_die(die), false);
  EXPECT_FALSE(r.interrupted);
  return done[key] = r.report;
}

fs::path output_of(const std::string& die, const std::string& folder = "a") { return suite_out() / folder / die; }

// Grain volume inside the cavity per 2 mm voxel, on a grid whose y faces are symmetric about the
// die's axis (y = 0), so that voxel j mirrors voxel ny - 1 - j.
std::vector<double> cavity_solid(const fs::path& particles_csv, const post::VoxelGrid& grid) {
  const dem::State s = dem::read_particles_csv(particles_csv, 0, 7800);
  std::vector<post::Grain> grains;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.x[i].z() < 0) grains.push_back({s.x[i], s.radius[i], 1.0});
  std::vector<double> solid(grid.size(), 0.0);
  post::bin_exact(grains, grid, solid);
  return solid;
}

double relative_l1(const std::vector<double>& a, const std::vector<double>& b) {
  double diff = 0, total = 0;
  for (std::size_t i = 0; i < a.size(); ++i) diff += std::abs(a[i] - b[i]), total += 0.5 * (a[i] + b[i]);
  return diff / total;
}

std::vector<double> mirrored_in_y(const std::vector<double>& f, const post::VoxelGrid& g) {
  std::vector<double> m(f.size());
  for (int i = 0; i < g.nx; ++i)
    for (int j = 0; j < g.ny; ++j)
      for (int k = 0; k < g.nz; ++k) m[g.index(i, j, k)] = f[g.index(i, g.ny - 1 - j, k)];
  return m;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

TEST(Pipeline, EveryInsertedGrainIsCountedAndNoneIsLost) {
  for (const char* die : {"ring", "disc"}) {
    const nlohmann::json& p = run(die, 0.1, 1)["particles"];
    const auto inserted = p["inserted"].get<std::int64_t>();
    EXPECT_GT(inserted, 1000) << die;
    EXPECT_GT(p["in_cavity"].get<std::int64_t>(), 100) << die;
    EXPECT_EQ(p["lost"].get<std::int64_t>(), 0) << die;
    // Inserted is the insertion's count, the rest the final state's: a grain the pass dropped
    // would show here.
    EXPECT_EQ(inserted, p["in_cavity"].get<std::int64_t>() + p["in_shoe"].get<std::int64_t>() +
                            p["elsewhere"].get<std::int64_t>() + p["spilled"].get<std::int64_t>())
        << die;
    // The particle file holds every inserted grain.
    EXPECT_EQ(dem::read_particles_csv(output_of(die) / "particles.csv", 0, 7800).size(), std::size_t(inserted)) << die;
  }
}

// The fill curve of the ring: it starts empty, rises without a dip while the die fills (to 90 %
// of its end, before the strike-off), and ends at the density field's mass, the report's
// fill.mass_kg (the same grains, the parts below the table: to the CSV's nine digits). After
// that the surface of the full die rattles: grains crossing the table's plane move it by up to
// 0.3 % (measured), which is why "monotone" holds for the filling only. Its chart is drawn.
TEST(Pipeline, FillCurveRisesWhileTheDieFillsAndEndsAtTheReportsMass) {
  const nlohmann::json& report = run("ring", 0.1, 1);
  std::ifstream csv(output_of("ring") / "fill_curve.csv");
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "t_s,shoe_x_m,grains_in_cavity,mass_in_cavity_kg,fraction_of_capacity");
  std::vector<double> time, mass;
  while (std::getline(csv, line)) {
    std::stringstream row(line);
    std::string cell[5];
    for (std::string& c : cell) std::getline(row, c, ',');
    time.push_back(std::stod(cell[0]));
    mass.push_back(std::stod(cell[3]));
  }
  ASSERT_GT(mass.size(), 100u);
  EXPECT_EQ(mass.front(), 0.0);
  const double end = report["fill"]["mass_kg"].get<double>();
  EXPECT_NEAR(mass.back(), end, 1e-8 * end);
  const std::size_t full = std::size_t(std::find_if(mass.begin(), mass.end(), [&](double m) { return m >= 0.9 * end; }) - mass.begin());
  ASSERT_LT(full, mass.size());
  EXPECT_LT(time[full], report["fill"]["strike_off_s"].get<double>());
  for (std::size_t k = 1; k <= full; ++k) EXPECT_GE(mass[k], mass[k - 1]) << "at t = " << time[k] << " s";
  // The capacity against the ring's own volume: two 104-gons (vertices on circles of 10 and 5 mm)
  // 10 mm deep, full of 7800 kg/m³; the STL holds its vertices as 32-bit floats (each within
  // 2^-24 of its coordinate), so the volume to three times that.
  const double ring_volume = 52 * std::sin(2 * std::numbers::pi / 104) * (100e-6 - 25e-6) * 10e-3;
  EXPECT_NEAR(report["fill"]["cavity_capacity_kg"].get<double>(), ring_volume * 7800, 3 * std::ldexp(1.0, -24) * ring_volume * 7800);
  EXPECT_TRUE(fs::exists(output_of("ring") / "fill_curve.png"));
}

// Every key of report.json has its row in docs/INTERFACE.md's table (with its unit and meaning),
// and every row names a key the report holds.
TEST(Pipeline, EveryReportKeyIsDocumented) {
  const nlohmann::json& report = run("ring", 0.1, 1);
  std::set<std::string> documented, written;
  std::ifstream doc(test::source_dir() / "docs" / "INTERFACE.md");
  bool in_table = false;
  for (std::string line; std::getline(doc, line);) {
    if (line.starts_with("- **Report** (`report.json`)")) in_table = true;
    else if (in_table && line.starts_with("- **")) break;
    if (in_table && line.starts_with("| `")) documented.insert(line.substr(3, line.find('`', 3) - 3));
  }
  // Leaves only, with the profiles' axes and the percentiles as the table writes them.
  const std::function<void(const nlohmann::json&, const std::string&)> walk = [&](const nlohmann::json& j, const std::string& path) {
    if (!j.is_object()) {
      written.insert(path);
      return;
    }
    for (const auto& [key, value] : j.items()) {
      std::string name = key;
      if (path.ends_with("profiles")) name = "<axis>";
      if (path.ends_with("percentiles")) name = "p<N>";
      if (path.ends_with("regions")) name = "<region>";
      walk(value, path.empty() ? name : path + "." + name);
    }
  };
  walk(report, "");
  ASSERT_GT(documented.size(), 50u) << "the table was not found";
  for (const std::string& key : written) EXPECT_TRUE(documented.count(key)) << key << " is not in docs/INTERFACE.md";
  for (const std::string& key : documented) EXPECT_TRUE(written.count(key)) << key << " is documented but not written";
}

// The top view is each column's cavity-weighted mean of the wall-corrected field, the values the
// sections show: along each section's voxel row the two agree to rounding, and no column reads
// below 0.3 where its section voxels read above 0.4. (The top view used to divide a column's raw
// solid by its sliver of cavity: eight rim columns of the ring at 0.05 where the section showed
// 0.41-0.60.)
TEST(Pipeline, TopViewAndSectionsShowTheSameWallCorrectedField) {
  run("ring", 0.1, 1);
  const nlohmann::json plot = nlohmann::json::parse(read_text(output_of("ring") / "plot_data.json"));
  const double h = plot["voxel_m"];
  int columns = 0;
  for (const bool along : {true, false}) {
    const nlohmann::json& section = plot["sections"][along ? "along" : "across"];
    const int axis = along ? 1 : 0;
    const int row = int(std::lround((section["at_m"].get<double>() - plot["origin_m"][axis].get<double>()) / h - 0.5));
    EXPECT_NEAR(section["at_m"].get<double>(), plot["centre_m"][axis].get<double>(), 1e-12) << "through the die's centre";
    const nlohmann::json& values = section["values"];
    for (std::size_t u = 0; u < values.size(); ++u) {
      double sum = 0, weight = 0, highest = -1;
      for (std::size_t k = 0; k < values[u].size(); ++k) {
        const double v = values[u][k], cavity = section["cavity_fraction"][u][k];
        if (v < 0) continue;
        sum += cavity * v, weight += cavity, highest = std::max(highest, v);
      }
      const double top = along ? plot["top_view"][u][std::size_t(row)] : plot["top_view"][std::size_t(row)][u];
      if (weight == 0) {
        EXPECT_EQ(top, -1.0);
        continue;
      }
      ++columns;
      EXPECT_NEAR(top, sum / weight, 1e-12) << (along ? "x" : "y") << " column " << u;
      if (highest > 0.4) {
        EXPECT_GE(top, 0.3) << (along ? "x" : "y") << " column " << u;
      }
    }
  }
  EXPECT_GE(columns, 4);
}

// The smoothed field (Gaussian of half a grain diameter, the kernel method) resolves the looser
// layer along the ring's outer wall that the grains' centres have: no centre lies within a
// radius of the wall, so the solid next to it is lower than one to two diameters in (measured:
// 0.515 in the first 0.4 mm against 0.566; the 3.2 mm voxels of the exact field cannot show it).
// Its profile away from the wall is the grain-centre profile (the cavity-grains' volume per
// shell volume, by distance from the wall) smoothed by the same kernel over the same cavity, in 1-D:
// within 0.03 (5 % of the fill) in every bin of half a kernel width to two grain diameters; the
// field is 3-D, curved and sampled on voxels, the prediction a flat wall sampled finely.
TEST(Pipeline, SmoothedFieldShowsTheWallLayerOfTheGrainCentres) {
  const nlohmann::json& report = run("ring", 0.1, 1);
  const double d = report["powder"]["grain_diameter_m"], width = report["fill"]["smoothed_width_m"];
  ASSERT_NEAR(width, d / 2, 1e-15) << "the default smoothed width";
  const dem::State s = dem::read_particles_csv(output_of("ring") / "particles.csv", 0, 7800);
  std::vector<post::Grain> grains;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.x[i].z() < 0 && s.x[i].z() > -10e-3 && s.x[i].head<2>().norm() > 5e-3 && s.x[i].head<2>().norm() < 10e-3)
      grains.push_back({s.x[i], s.radius[i], 1.0});
  const mesh::PreparedDie die = mesh::prepare_die(bundled_die("ring"), mesh::die_options_for_grains(d / 2, d / 4), std::nullopt);
  const geometry::WallField walls = die.sdf.wall_field(die.solid);
  pipeline::DensityOptions settings;
  settings.voxel_m = 2 * d;
  settings.smoothed_width_m = width;
  const pipeline::DensityResult field = pipeline::compute_density(grains, die, walls, 7800, settings, "ring");
  ASSERT_TRUE(field.smoothed.has_value());
  // Voxels 3 widths clear of the floor and the table; the grain-centre profile from the grains
  // their kernels reach.
  const double z_lo = -10e-3 + 3 * width, z_hi = -3 * width, step = d / 32, outer = 10e-3, gap = 5e-3;
  const int shells = int(std::lround(gap / step));
  std::vector<double> centres(std::size_t(shells), 0.0);
  for (const post::Grain& g : grains) {
    if (g.centre.z() < z_lo - 3 * width || g.centre.z() > z_hi + 3 * width) continue;
    const int b = int((outer - g.centre.head<2>().norm()) / step);
    if (b >= 0 && b < shells) centres[std::size_t(b)] += 4.0 / 3.0 * std::numbers::pi * std::pow(g.radius, 3);
  }
  for (int b = 0; b < shells; ++b) {
    const double r0 = outer - (b + 1) * step, r1 = outer - b * step;
    centres[std::size_t(b)] /= std::numbers::pi * (r1 * r1 - r0 * r0) * (z_hi - z_lo + 6 * width);
  }
  const auto predicted = [&](double rho) {  // the 1-D kernel method on the shells
    double solid = 0, cavity = 0;
    for (int b = 0; b < shells; ++b) {
      const double u = (b + 0.5) * step - rho, k = std::exp(-0.5 * u * u / (width * width));
      solid += k * centres[std::size_t(b)], cavity += k;
    }
    return solid / cavity;
  };
  const post::DensityField& f = *field.smoothed;
  const double bin = width / 2;
  const int bins = int(std::lround(2 * d / bin));
  std::vector<double> measured(std::size_t(bins), 0.0), expected(std::size_t(bins), 0.0), count(std::size_t(bins), 0.0);
  for (int i = 0; i < f.grid.nx; ++i)
    for (int j = 0; j < f.grid.ny; ++j)
      for (int k = 0; k < f.grid.nz; ++k) {
        const post::Vec3 c = f.grid.centre(i, j, k);
        const double rho = outer - c.head<2>().norm(), value = f.corrected.solid_fraction[f.grid.index(i, j, k)];
        const int b = int(std::floor(rho / bin));
        if (c.z() < z_lo || c.z() > z_hi || b < 0 || b >= bins || !std::isfinite(value)) continue;
        measured[std::size_t(b)] += value, expected[std::size_t(b)] += predicted(rho), count[std::size_t(b)] += 1;
      }
  double inner = 0, inner_voxels = 0;
  for (int b = 0; b < bins; ++b) {
    ASSERT_GT(count[std::size_t(b)], 10) << "bin " << b;
    const double m = measured[std::size_t(b)] / count[std::size_t(b)], e = expected[std::size_t(b)] / count[std::size_t(b)];
    std::printf("%.2f mm from the outer wall: smoothed field %.4f, grain-centre profile smoothed %.4f\n", (b + 0.5) * bin * 1e3, m, e);
    EXPECT_NEAR(m, e, 0.03) << (b + 0.5) * bin * 1e3 << " mm from the wall";
    if ((b + 0.5) * bin > d) inner += measured[std::size_t(b)], inner_voxels += count[std::size_t(b)];
  }
  // The wall layer, beyond what the agreement allows: the bin at the wall against one to two
  // diameters in.
  EXPECT_LT(measured[0] / count[0], inner / inner_voxels - 0.03) << "the layer at the wall is looser";
}

// `diefill compare` on two seeds of the same scene: the fill statistics side by side with their
// differences, and the difference field, read back, B - A voxel by voxel (float32 grids); a run
// against itself differs by nothing; another die is refused.
TEST(Pipeline, CompareGivesTheDifferenceOfTwoSeeds) {
  const nlohmann::json& one = run("ring", 0.1, 1, "a");
  const nlohmann::json& two = run("ring", 0.1, 2, "seed2");
  const fs::path out = suite_out() / "compare";
  const nlohmann::json c = pipeline::compare_runs(output_of("ring", "a"), output_of("ring", "seed2"), out);
  EXPECT_TRUE(c["same_scene"].get<bool>());
  EXPECT_EQ(c["seeds"], nlohmann::json({1, 2}));
  EXPECT_DOUBLE_EQ(c["fill"]["fill_ratio"]["difference"].get<double>(),
                   two["fill"]["fill_ratio"].get<double>() - one["fill"]["fill_ratio"].get<double>());
  EXPECT_DOUBLE_EQ(c["fill"]["regions"]["near_wall"]["a"].get<double>(), one["fill"]["regions"]["near_wall"]["fill_ratio"].get<double>());
  EXPECT_EQ(c["field"]["voxels"], one["fill"]["voxels"]);
  EXPECT_GT(c["field"]["rms_difference"].get<double>(), 0.0);
  EXPECT_TRUE(c.contains("smoothed_field"));
  const auto difference = post::read_vdb(out / "difference.vdb");
  const auto a = post::read_vdb(output_of("ring", "a") / "density.vdb"), b = post::read_vdb(output_of("ring", "seed2") / "density.vdb");
  const auto& delta = difference.at("solid_fraction_difference").values;
  ASSERT_EQ(delta.size(), c["field"]["voxels"].get<std::size_t>());
  for (const auto& [index, value] : delta)
    EXPECT_NEAR(value, b.at("solid_fraction").values.at(index) - a.at("solid_fraction").values.at(index), 1e-6);
  EXPECT_TRUE(fs::exists(out / "compare.png"));
  const nlohmann::json itself = pipeline::compare_runs(output_of("ring", "a"), output_of("ring", "a"), suite_out() / "compare_itself");
  EXPECT_EQ(itself["field"]["largest_difference"].get<double>(), 0.0);
  EXPECT_EQ(itself["fill"]["fill_ratio"]["difference"].get<double>(), 0.0);
  run("disc", 0.1, 1);
  EXPECT_THROW(pipeline::compare_runs(output_of("ring"), output_of("disc"), suite_out() / "compare_dies"), diefill::InputError);
  EXPECT_FALSE(fs::exists(suite_out() / "compare_dies")) << "nothing written for a refused comparison";
}

// The FEM hand-off of a run (docs/INTERFACE.md, "FEM hand-off"): on the ring and the disc the
// elements hold the grains' mass in the cavity (of each grain whose centre lies in the cavity, its
// part below the table: fill.mass_kg's definition; summed here from particles.csv with the
// spherical cap's volume) within 0.5 %, as the report measures it with nothing rescaled, and fill
// the cavity's volume within 0.5 %; no element is inverted; the elements along the walls and the
// others read the grains' own solid there (random points inside grains, tests/fem_wall_layer.py)
// to 0.016 (the lattice's bound per element, tests/test_fem.cpp) and three sampling deviations,
// so the looser wall layer stays in them, at least as deep as the smoothed field shows it;
// CalculiX reads the deck without a warning and the punch runs.
TEST(Pipeline, FemHandOffHoldsTheCavitysMassAndItsWallLayer) {
  for (const std::string die : {"ring", "disc"}) {
    const nlohmann::json& report = run(die, 0.1, 1);
    const nlohmann::json& fem = report.at("fem");
    const dem::State s = dem::read_particles_csv(output_of(die) / "particles.csv", 0, 7800);
    double below_table = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
      const double r = s.radius[i], z = s.x[i].z();
      if (s.x[i].head<2>().norm() > 10e-3 || z > 0) continue;  // centre outside the Ø20 mm cavity
      const double h = std::clamp(r - z, 0.0, 2 * r);                 // the cap below the table
      below_table += std::numbers::pi * h * h * (3 * r - h) / 3;
    }
    const double mass = below_table * report["powder"]["material_density"].get<double>();
    std::printf("%s: %zu elements, mass %.6g kg against %.6g kg in the cavity, volume %+.3f %%, dihedral >= %.1f°, "
                "axial stress %.4g (densest quarter) and %.4g MPa (loosest)\n",
                die.c_str(), fem["elements"].get<std::size_t>(), fem["mass_kg"].get<double>(), mass,
                100 * fem["volume_error_rel"].get<double>(), fem["min_dihedral_deg"].get<double>(),
                fem["compaction"]["densest_quarter_axial_stress_pa"].get<double>() / 1e6,
                fem["compaction"]["loosest_quarter_axial_stress_pa"].get<double>() / 1e6);
    EXPECT_NEAR(fem["mass_kg"].get<double>() / mass, 1.0, 0.005) << die;
    EXPECT_LE(std::abs(fem["mass_error_rel"].get<double>()), 0.005) << die;
    EXPECT_FALSE(fem.contains("mass_scale")) << "nothing is rescaled";
    EXPECT_TRUE(report["stability"]["checks"]["fem_mass_within_half_percent"].get<bool>()) << die;
    EXPECT_NEAR(fem["volume_error_rel"].get<double>(), 0.0, 0.005) << die;
    EXPECT_EQ(fem["inverted_elements"].get<int>(), 0) << die;
    EXPECT_GT(fem["min_dihedral_deg"].get<double>(), 10.0) << die;

    const test::Run py = test::run_command("/usr/bin/python3 " + (test::source_dir() / "tests" / "fem_wall_layer.py").string() +
                                           " " + output_of(die).string() + " 2>&1");
    ASSERT_EQ(py.status, 0) << py.output;
    const nlohmann::json layer = nlohmann::json::parse(py.output);
    for (const char* part : {"wall", "interior"}) {
      const nlohmann::json& l = layer[part];
      std::printf("%s, elements %s: %d, solid fraction %.4f, grains' own %.4f (sampling %.4f), smoothed field %.4f\n", die.c_str(),
                  part, l["elements"].get<int>(), l["element_mean"].get<double>(), l["truth_mean"].get<double>(),
                  l["truth_sigma"].get<double>(), l["smoothed_mean"].get<double>());
      EXPECT_NEAR(l["element_mean"].get<double>(), l["truth_mean"].get<double>(), 0.016 + 3 * l["truth_sigma"].get<double>())
          << die << " " << part;
    }
    const auto drop = [&](const char* mean) { return layer["interior"][mean].get<double>() - layer["wall"][mean].get<double>(); };
    EXPECT_GE(drop("element_mean"), drop("smoothed_mean")) << die << ": the elements lost the wall layer the smoothed field shows";

    const std::string log = read_text(output_of(die) / "fem" / "ccx.log");
    EXPECT_EQ(log.find("WARNING"), std::string::npos) << log;
    EXPECT_EQ(log.find("ERROR"), std::string::npos) << log;
    EXPECT_GT(fem["compaction"]["punch_force_n"].get<double>(), 0.0) << die << ": the punch presses (compressive positive)";
    EXPECT_TRUE(fs::exists(output_of(die) / "fem" / "compaction.png")) << die;
  }
}

// A sweep over three shoe speeds: one folder per case, the summary table and chart; each case is
// bit for bit the run `--set motion.speed=...` gives (the same final state and particle file).
TEST(PipelineOwnRuns, SweepRunsEachCaseAsItsSingleRun) {
  // The disc at 2.26 mm grains: what is asserted is that a case is its single run, bit for bit.
  const fs::path base = suite_out() / "sweep";
  const std::string cache = "output.cache=" + (suite_out() / "sweep_cache").string();
  const auto load = [&](const std::vector<std::string>& more) {
    std::vector<std::string> overrides = {"simulation.seed=1", "output.directory=" + base.string(), cache, "powder.coarse_graining=22.6",
                                          "motion.die_settle_time=0.01", "fem.elements=none"};
    overrides.insert(overrides.end(), more.begin(), more.end());
    scene::PipelineScene scene = scene::load_pipeline_scene(std::nullopt, overrides);
    scene.die.file = bundled_die("disc");
    scene.pictures = false;  // the sweep's own chart is drawn regardless
    return scene;
  };
  const pipeline::Sweep sweep = pipeline::parse_sweep("motion.speed=0.1,0.2,0.4");
  const std::vector<pipeline::DieRun> runs = pipeline::run_sweep(load, sweep, nullptr);
  ASSERT_EQ(runs.size(), 3u);
  const double speeds[] = {0.1, 0.2, 0.4};
  for (std::size_t k = 0; k < 3; ++k) {
    const std::string folder = "single" + sweep.values[k];
    const nlohmann::json& single = run("disc", speeds[k], 1, folder, "powder.coarse_graining=22.6 motion.die_settle_time=0.01 " + cache);
    EXPECT_EQ(runs[k].dir, base / ("motion.speed=" + sweep.values[k]) / "disc");
    EXPECT_EQ(runs[k].report["final_state_sha256"], single["final_state_sha256"]) << "at " << speeds[k] << " m/s";
    EXPECT_EQ(read_text(runs[k].dir / "particles.csv"), read_text(output_of("disc", folder) / "particles.csv")) << speeds[k];
  }
  const std::string table = read_text(base / "sweep_motion.speed.csv");
  EXPECT_EQ(std::count(table.begin(), table.end(), '\n'), 4) << table;
  EXPECT_TRUE(fs::exists(base / "sweep_motion.speed.png"));
  EXPECT_THROW(pipeline::parse_sweep("motion.speed"), diefill::InputError);
  EXPECT_THROW(pipeline::run_sweep(load, pipeline::parse_sweep("output.directory=a,b"), nullptr), diefill::InputError);
  // A bad last value is refused before the first case runs.
  EXPECT_THROW(pipeline::run_sweep(load, pipeline::parse_sweep("powder.coarse_graining=16,-1"), nullptr), diefill::InputError);
  EXPECT_FALSE(fs::exists(base / "powder.coarse_graining=16")) << "no case ran";
}

// The ring and the shoe are symmetric about the line of motion (y = 0); only the random packing
// is not. The field's mirror difference must be no larger than the difference between two seeds
// (both are sums of the same packing noise; 1.25 allows for the sampling spread of two numbers).
TEST(Pipeline, RingFieldIsMirrorSymmetricWithinTheSeedNoise) {
  run("ring", 0.1, 1, "a");
  run("ring", 0.1, 2, "seed2");
  post::VoxelGrid grid;
  grid.origin = post::Vec3(-10e-3, -10e-3, -10e-3);
  grid.voxel = 2e-3;
  grid.nx = grid.ny = 10, grid.nz = 5;
  const auto one = cavity_solid(output_of("ring", "a") / "particles.csv", grid);
  const auto two = cavity_solid(output_of("ring", "seed2") / "particles.csv", grid);
  const double seed_noise = relative_l1(one, two);
  const double mirror_one = relative_l1(one, mirrored_in_y(one, grid));
  const double mirror_two = relative_l1(two, mirrored_in_y(two, grid));
  RecordProperty("seed_noise", std::to_string(seed_noise));
  std::printf("relative L1 difference per 2 mm voxel: between seeds %.4f, mirror (seed 1) %.4f, mirror (seed 2) %.4f\n",
              seed_noise, mirror_one, mirror_two);
  EXPECT_GT(seed_noise, 0.0);
  EXPECT_LE(0.5 * (mirror_one + mirror_two), 1.25 * seed_noise);
}

// The outputs as other tools read them: OpenVDB's Python module, VTK and meshio (not our code),
// against the report, the die file's own SHA-256 and the particle file.
TEST(Pipeline, OutputsReadBackThroughOtherToolsWithTheRightValues) {
  const nlohmann::json& r = run("ring", 0.1, 1);
  const std::string command = "/usr/bin/python3 " + (test::source_dir() / "tests" / "read_outputs.py").string() + " " +
                              output_of("ring").string() + " " + bundled_die("ring").string() + " 2>&1";
  const test::Run py = test::run_command(command);
  ASSERT_EQ(py.status, 0) << py.output;
  const nlohmann::json j = nlohmann::json::parse(py.output);
  EXPECT_EQ(j["vdb_names"], nlohmann::json({"cavity_fraction", "density", "merged", "smoothed_cavity_fraction",
                                            "smoothed_density", "smoothed_solid_fraction", "solid_fraction"}));
  EXPECT_EQ(j["vdb_merged_voxels"], r["fill"]["merged_voxels"]);
  // The smoothed field: voxels as wide as its Gaussian, half a grain diameter by default.
  EXPECT_DOUBLE_EQ(j["vdb_smoothed_width_m"].get<double>(), r["fill"]["smoothed_width_m"].get<double>());
  EXPECT_DOUBLE_EQ(j["vdb_smoothed_width_m"].get<double>(), 0.5 * r["powder"]["grain_diameter_m"].get<double>());
  EXPECT_NEAR(j["vdb_smoothed_voxel_m"].get<double>(), j["vdb_smoothed_width_m"].get<double>(), 1e-12);
  EXPECT_NEAR(j["smoothed_vti_spacing_m"].get<double>(), j["vdb_smoothed_width_m"].get<double>(), 1e-12);
  EXPECT_EQ(j["vdb_metadata"]["die_sha256"], j["die_sha256"]);
  EXPECT_EQ(j["vdb_metadata"]["die"], "ring");
  EXPECT_EQ(j["vdb_metadata"]["coarse_graining"], "16");
  EXPECT_EQ(j["vdb_metadata"]["units"], "m");
  EXPECT_EQ(j["vdb_metadata"]["method"], "exact");
  // The default density voxel is two grain diameters.
  EXPECT_DOUBLE_EQ(j["vdb_voxel_m"].get<double>(), 2 * r["powder"]["grain_diameter_m"].get<double>());
  EXPECT_NEAR(j["vti_spacing_m"].get<double>(), j["vdb_voxel_m"].get<double>(), 1e-12);
  // The cavity and its mean solid fraction as the report has them (float32 grids: 1e-6 relative).
  EXPECT_NEAR(j["vdb_cavity_volume_m3"].get<double>(), r["fill"]["cavity_volume_m3"].get<double>(),
              1e-6 * r["fill"]["cavity_volume_m3"].get<double>());
  EXPECT_NEAR(j["vdb_solid_fraction_mean"].get<double>(), r["fill"]["solid_fraction_mean"].get<double>(), 1e-6);
  EXPECT_EQ(j["vti_arrays"], nlohmann::json({"cavity_fraction", "density", "merged", "solid_fraction"}));
  EXPECT_LT(j["vti_vdb_max_difference"].get<double>(), 1e-5);  // six significant digits in the VTI
  EXPECT_EQ(j["vtu_points"], r["particles"]["inserted"]);
  EXPECT_EQ(j["csv_rows"], r["particles"]["inserted"]);
  // The VTU keeps nine significant digits (half a unit in the ninth of 1 mm and 30 mm).
  EXPECT_LT(j["vtu_csv_max_radius_difference"].get<double>(), 5e-12);
  EXPECT_LT(j["vtu_csv_max_position_difference"].get<double>(), 1.5e-10);
}

// Results do not depend on the thread count, nor on anything but the scene and the seed: the
// shoe settled and moved on two threads ends in the very state (every position, velocity and
// contact history) one thread gives, and the whole report (FEM hand-off included) is the same but
// for its timing. Each run settles its own shoe, so a run's repeat on one thread count is
// implied. The disc at 2.26 mm grains (about 700, split over both threads' blocks): thread counts
// change no bit whatever the scene's size (docs/ARCHITECTURE.md, "Model and state").
TEST(PipelineOwnRuns, TwoThreadsGiveTheSameReportStateAndGrainsAsOne) {
  const std::string tiny = "powder.coarse_graining=22.6 motion.die_settle_time=0.01 fem.elements=linear";
  nlohmann::json one = run("disc", 0.1, 1, "one_thread", tiny + " simulation.threads=1");
  nlohmann::json two = run("disc", 0.1, 1, "two_threads", tiny + " simulation.threads=2");
  EXPECT_EQ(one["timing"]["threads_per_rank"], 1);
  EXPECT_EQ(two["timing"]["threads_per_rank"], 2);
  ASSERT_TRUE(one.contains("fem"));
  one.erase("timing"), two.erase("timing");
  EXPECT_EQ(one.dump(), two.dump());
  EXPECT_EQ(read_text(output_of("disc", "one_thread") / "particles.csv"), read_text(output_of("disc", "two_threads") / "particles.csv"));
}

// docs/PHYSICS.md §3: below the critical speed the cavity fills to the powder's poured density; above
// it less and less powder has time to fall in. Grains of 1.2 mm: the layer of looser packing
// along the cavity's walls (about a quarter diameter thick) costs 0.6 x 1.2 x 0.25 x A/V = 0.07
// of the disc's fill at this size, 0.09 with 1.6 mm grains, which would put a slow shoe's fill
// below the poured density's range for a reason that is not the shoe (measured: 0.479 at 1.6 mm).
// A 6 mm powder bed holds about 1.5 times what the disc takes. Measured (2026-12-06, seed 1):
// 0.565 at 0.05 m/s, 0.560 at 0.1, 0.501 at 0.25: 0.1 m/s is still below the critical speed.
TEST(PipelineOwnRuns, FillRatioFallsWithShoeSpeedFromThePouredDensity) {
  const std::string finer = "powder.coarse_graining=12 shoe.fill_height=0.006";
  const double speeds[] = {0.1, 0.25, 0.7};
  double previous = 1;
  for (double v : speeds) {
    const double fill = run("disc", v, 1, "finer", finer)["fill"]["fill_ratio"].get<double>();
    std::printf("disc, shoe at %.3g m/s: fill ratio %.4f\n", v, fill);
    if (v == speeds[0]) {
      EXPECT_GE(fill, 0.50);
      EXPECT_LE(fill, 0.64);
    }
    EXPECT_LT(fill, previous) << "at " << v << " m/s";
    previous = fill;
  }
  // The settled shoe is cached once and reused at every speed.
  std::size_t settled = 0;
  for (const auto& e : fs::directory_iterator(suite_out() / "finer" / ".cache"))
    settled += e.path().filename().string().starts_with("shoe-");
  EXPECT_EQ(settled, 1u);
}

// Modelling no more than the scene needs: the powder beyond the die's width plus a margin never
// reaches the cavity, so the trimmed shoe must fill the die as the full 50 mm shoe does, within
// the spread between seeds (seeds 1 and 2 differ by 0.006 in fill ratio, RingFieldIsMirror...
// runs both; the bound allows three times that).
TEST(Pipeline, TrimmedShoeFillsLikeTheFullShoe) {
  const double trimmed = run("ring", 0.1, 1)["fill"]["fill_ratio"].get<double>();
  const double full = run("ring", 0.1, 1, "full", coarse + " shoe.trim_width=false")["fill"]["fill_ratio"].get<double>();
  std::printf("ring fill ratio: trimmed shoe %.4f, full shoe %.4f\n", trimmed, full);
  EXPECT_LT(std::abs(full - trimmed), 0.02);
}

// Capsule grains as rigid clumps: poured through the shoe into the ring they stay in the die,
// every grain is counted once, and the binned volume is the grains' true volume (not the sum of
// their overlapping members').
TEST(PipelineOwnRuns, ClumpGrainsFillTheRingWithoutLeaking) {
  REQUIRE_SHARED_MESHES();
  const std::string capsule = (test::shared_meshes() / "grains" / "capsule_trimesh.obj").string();
  // A fast shoe: what is checked is the census and the binned volume, not the fill's size.
  const nlohmann::json& r = run("ring", 0.3, 1, "clumps",
                                coarse + " motion.acceleration=20 powder.shape.mesh=\"" + capsule + "\" powder.shape.tolerance=0.05");
  test::expect_clump_fill_census(r);
  const nlohmann::json& p = r["particles"];
  std::printf("ring with capsule clumps: %lld of %lld grains in the cavity, fill ratio %.4f\n",
              (long long)p["in_cavity"].get<std::int64_t>(), (long long)p["inserted"].get<std::int64_t>(),
              r["fill"]["fill_ratio"].get<double>());
}

// This mesh's shells pass every check we can make, yet CGAL's corefinement crashed on them in
// the pipeline's coarser repair settings; the union runs in a child process. Its folds are now
// re-meshed and its shells united, and the run stops where it should, clearly: the mesh has no
// flat top face, so it is no die cavity. Told that its opening faces +z, it goes through the
// repair to that message; left to find its opening, it is refused as it is read, as having no
// flat face at any extreme. Both with die.parting = "opening": the default would cut the part
// at its widest section instead.
TEST(PipelineOwnRuns, MeshThatCrashedCorefinementIsRefusedClearly) {
  REQUIRE_SHARED_MESHES();
  for (const auto& [up, message] : {std::pair{"+z", "no flat top face"}, std::pair{"auto", "no flat face at its extreme"}}) {
    scene::PipelineScene scene = scene::load_pipeline_scene(
        std::nullopt, {"powder.max_grains=3000", std::string("die.up=") + up, "die.parting=opening", "output.directory=" + (suite_out() / "refused").string()});
    try {
      pipeline::run_die_fill(scene, test::shared_meshes() / "dies" / "broken" / "assimp_3DSMaxExport.stl", false);
      ADD_FAILURE() << "the mesh was accepted";
    } catch (const diefill::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("assimp_3DSMaxExport.stl"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
}

// A shoe from a mesh (in its own frame: origin at the inner centre, on the table) fills the die
// as the built-in box of the same size does.
TEST(Pipeline, ShoeFromAMeshFillsLikeTheBox) {
  test::TempDir dir;
  // The box shoe trimmed to the ring: 32 mm long, 20 + 2 x 4 mm wide, 37 mm high, 3 mm walls.
  mesh::write_stl(mesh::shoe_solid(32e-3, 28e-3, 37e-3, 3e-3), dir / "shoe.stl", geometry::LengthUnit::mm, "shoe");
  const double box = run("ring", 0.1, 1)["fill"]["fill_ratio"].get<double>();
  const nlohmann::json& r = run("ring", 0.1, 1, "mesh_shoe", coarse + " shoe.mesh=\"" + (dir / "shoe.stl").string() + "\"");
  const double from_mesh = r["fill"]["fill_ratio"].get<double>();
  std::printf("ring fill ratio: box shoe %.4f, shoe from a mesh %.4f\n", box, from_mesh);
  EXPECT_EQ(r["particles"]["lost"].get<std::int64_t>(), 0);
  EXPECT_LT(std::abs(from_mesh - box), 0.02);  // three times the seed spread, as above
}

// Ctrl-C during the fill keeps a checkpoint; `run --resume` finishes from it with the same
// result as an uninterrupted run, bit for bit: the same report (timings aside), final state and
// grains, and the same fill curve and snapshot series, the parts written before the interrupt
// included (none written over by the resumed run).
TEST(PipelineOwnRuns, InterruptedRunResumesToTheSameResult) {
  test::TempDir dir;
  // A fast shoe and no FEM hand-off: the resume's bits do not depend on the fill's size.
  const std::string args = "run " + bundled_die("ring").string() + " --out " + dir.path().string() + " --set " + coarse +
                           " --set motion.speed=0.4 --set motion.die_settle_time=0.01 --set fem.elements=none" +
                           " --set output.snapshot_every=0.02";
  const test::Run whole = test::run_diefill(args);
  ASSERT_EQ(whole.status, 0) << whole.output;
  nlohmann::json expected = nlohmann::json::parse(test::read_text(dir / "ring" / "report.json"));
  const std::string expected_grains = test::read_text(dir / "ring" / "particles.csv");
  const auto series = [&] {  // the fill curve, series.pvd and every snapshot of grains and shoe, by name
    std::map<std::string, std::string> files;
    for (const auto& f : fs::directory_iterator(dir / "ring")) {
      const std::string name = f.path().filename().string();
      if (name == "fill_curve.csv" || name == "series.pvd" || name.starts_with("snapshot_") || name.starts_with("shoe_"))
        files[name] = test::read_text(f.path());
    }
    return files;
  };
  const std::map<std::string, std::string> expected_series = series();
  ASSERT_GT(expected_series.size(), 10u);
  // The die and the settled shoe are cached now: the fill starts within a second or two, and
  // lasts about five; stopped a second into it (its first progress line).
  const fs::path status = dir / "status", log = dir / "stopped.log";
  const std::string interrupt = "bash -c '" + std::string(DIEFILL_EXECUTABLE) + " " + args + " > " + log.string() +
                                " 2>&1 & pid=$!; for i in $(seq 300); do grep -q filling: " + log.string() +
                                " && break; sleep 0.1; done; sleep 1; kill -INT $pid; wait $pid; echo $? > " + status.string() + "'";
  ASSERT_EQ(std::system(interrupt.c_str()), 0);
  EXPECT_EQ(test::read_text(status), "130\n") << test::read_text(log);
  EXPECT_TRUE(fs::exists(dir / "ring" / "checkpoint.bin"));
  // The earlier outputs survive the interrupted run.
  EXPECT_TRUE(fs::exists(dir / "ring" / "density.vdb"));
  const test::Run resumed = test::run_diefill(args + " --resume");
  ASSERT_EQ(resumed.status, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("resumed at"), std::string::npos) << resumed.output;
  nlohmann::json got = nlohmann::json::parse(test::read_text(dir / "ring" / "report.json"));
  expected.erase("timing"), got.erase("timing");
  EXPECT_EQ(got.dump(), expected.dump());
  EXPECT_EQ(got["final_state_sha256"], expected["final_state_sha256"]);
  EXPECT_EQ(test::read_text(dir / "ring" / "particles.csv"), expected_grains);
  const std::map<std::string, std::string> got_series = series();
  EXPECT_EQ(got_series.size(), expected_series.size());
  for (const auto& [name, text] : expected_series) EXPECT_TRUE(got_series.contains(name) && got_series.at(name) == text) << name;
  EXPECT_FALSE(fs::exists(dir / "ring" / "checkpoint_outputs.json")) << "a finished run removes it with the checkpoint";
}

// Above the critical speed one pass leaves the die short; going back and forth gives the powder
// more time over the opening, so two passes with returns fill it further (the seed study's
// multi-pass result). A return stroke sweeps the grains the strike-off left on the table ahead of
// the shoe's wall and lets them go at the shoe's speed when it stops, and a sphere held back by
// rolling friction alone (μ_r = 0.1) rolls on for about ten centimetres: such grains may leave over the
// table's end. They are counted as spilled (a leak through the die would have failed the run).
TEST(PipelineOwnRuns, MorePassesFillAFastShoesDieFurther) {
  const double once = run("disc", 0.4, 1, "passes", coarse + " fem.elements=none")["fill"]["fill_ratio"].get<double>();
  const nlohmann::json& r = run("disc", 0.4, 1, "passes", coarse + " motion.passes=2 motion.return=true");
  const double twice = r["fill"]["fill_ratio"].get<double>();
  std::printf("disc at 0.4 m/s: fill ratio one pass %.4f, two passes with returns %.4f\n", once, twice);
  const nlohmann::json& p = r["particles"];
  EXPECT_EQ(p["inserted"].get<std::int64_t>(), p["in_cavity"].get<std::int64_t>() + p["in_shoe"].get<std::int64_t>() +
                                                    p["elsewhere"].get<std::int64_t>() + p["spilled"].get<std::int64_t>());
  EXPECT_EQ(p["lost"].get<std::int64_t>(), 0);
  EXPECT_LT(p["spilled"].get<std::int64_t>(), p["elsewhere"].get<std::int64_t>()) << "most swept grains stay on the table";
  EXPECT_GT(twice, once + 0.02);  // three times the seed spread
}

// A folder run takes the mesh files only: a README or a log beside the dies is passed over, not
// refused as a broken mesh.
TEST(PipelineOwnRuns, FolderRunPassesOverFilesThatAreNotMeshes) {
  test::TempDir dir;
  fs::create_directories(dir / "dies");
  fs::copy_file(bundled_die("disc"), dir / "dies" / "disc.stl");
  test::write_text(dir / "dies" / "README.md", "# my dies\n");
  test::write_text(dir / "dies" / "notes.log", "run at 9am\n");
  const test::Run r = test::run_diefill("run " + (dir / "dies").string() + " --out " + (dir / "out").string() +
                                        " --set powder.coarse_graining=22.6 --set fem.elements=none" +
                                        " --set motion.speed=0.4 --set motion.die_settle_time=0.01");
  EXPECT_EQ(r.status, 0) << r.output;
  const std::string summary = test::read_text(dir / "out" / "summary.csv");
  EXPECT_NE(summary.find("disc,ok"), std::string::npos) << summary;
  EXPECT_EQ(summary.find("README"), std::string::npos) << summary;
  EXPECT_EQ(summary.find("notes"), std::string::npos) << summary;
}

// The shoe holds the bed it is asked for: random insertion jams near a third of the volume, so a
// bed of 18.5 mm needs more than one round (it delivered 82 % of its grains, silently).
TEST(PipelineOwnRuns, ShoeIsFilledToTheBedHeightAsked) {
  const nlohmann::json& r = run("ring", 0.4, 1, "deep_bed", coarse + " shoe.fill_height=0.0185 motion.die_settle_time=0.01");
  EXPECT_EQ(r["powder"]["grains"], r["powder"]["grains_requested"]) << r["powder"].dump();
  EXPECT_TRUE(r["stability"]["warnings"].empty()) << r["stability"].dump();
}

// The settled shoe is settled again when a key that shapes it changes, and reused when only the
// shoe's motion does.
TEST(PipelineOwnRuns, SettledShoeIsRebuiltWhenASettlingKeyChanges) {
  const auto shoes = [] {
    std::size_t n = 0;
    for (const auto& e : fs::directory_iterator(suite_out() / "resettle" / ".cache")) n += e.path().filename().string().starts_with("shoe-");
    return n;
  };
  const std::string fast = "powder.coarse_graining=22.6 motion.die_settle_time=0.01";  // the cache's keys, not the fill
  run("disc", 0.4, 1, "resettle", fast);
  run("disc", 0.5, 1, "resettle", fast);
  EXPECT_EQ(shoes(), 1u) << "another speed reuses the settled shoe";
  run("disc", 0.4, 1, "resettle", fast + " motion.shoe_settle_time=0.07");
  EXPECT_EQ(shoes(), 2u) << "another settling time settles again";
}

// A seed ensemble (pipeline/ensemble.hpp) through the command line: two seeds of the disc at
// 2.26 mm grains, each its own run in OUT/simulation.seed=K/disc/, and their ensemble in
// OUT/disc/, whose fill ratio is the two reports' mean with half their difference as its
// standard error, whose density.vdb holds per voxel the mean of the two fields and half their
// difference (solid_fraction_stderr; the grids are 32-bit floats), and whose FEM hand-off holds
// each element's standard error.
TEST(PipelineOwnRuns, SeedEnsembleIsTheMeanOfItsSeedsRuns) {
  const fs::path out = suite_out() / "ensemble";
  const test::Run r = test::run_diefill("run " + bundled_die("disc").string() + " --seeds 2 --out " + out.string() +
                                        " --set powder.coarse_graining=22.6 --set fem.compaction=none --set motion.die_settle_time=0.01" +
                                        // elements of 4.5 mm would miss 1 % of the disc's volume at its rim
                                        " --set fem.element_size=0.002");
  ASSERT_EQ(r.status, 0) << r.output;
  const auto report = [&](const fs::path& dir) { return nlohmann::json::parse(read_text(dir / "report.json")); };
  const nlohmann::json one = report(out / "simulation.seed=1" / "disc"), two = report(out / "simulation.seed=2" / "disc");
  const nlohmann::json both = report(out / "disc");
  const double a = one["fill"]["fill_ratio"].get<double>(), b = two["fill"]["fill_ratio"].get<double>();
  EXPECT_NE(a, b);
  EXPECT_NEAR(both["fill"]["fill_ratio"].get<double>(), 0.5 * (a + b), 1e-15);
  EXPECT_NEAR(both["fill"]["fill_ratio_stderr"].get<double>(), 0.5 * std::abs(a - b), 1e-15);
  EXPECT_EQ(both["run"]["seeds"], nlohmann::json({1, 2}));
  EXPECT_TRUE(both["stability"]["checks_passed"].get<bool>()) << both["stability"].dump();
  const auto fa = post::read_vdb(out / "simulation.seed=1" / "disc" / "density.vdb");
  const auto fb = post::read_vdb(out / "simulation.seed=2" / "disc" / "density.vdb");
  const auto fm = post::read_vdb(out / "disc" / "density.vdb");
  ASSERT_TRUE(fm.count("solid_fraction_stderr") && fm.count("smoothed_solid_fraction_stderr"));
  std::size_t checked = 0;
  for (const auto& [index, mean] : fm.at("solid_fraction").values) {
    const double x = fa.at("solid_fraction").values.at(index), y = fb.at("solid_fraction").values.at(index);
    EXPECT_NEAR(mean, 0.5 * (x + y), 1e-6);
    EXPECT_NEAR(fm.at("solid_fraction_stderr").values.at(index), 0.5 * std::abs(x - y), 1e-6);
    ++checked;
  }
  EXPECT_GT(checked, 50u);
  EXPECT_NE(read_text(out / "disc" / "fem" / "fill.vtu").find("Name=\"solid_fraction_stderr\""), std::string::npos);
  EXPECT_NE(read_text(out / "disc" / "fill_curve.csv").find("mass_in_cavity_kg_stderr"), std::string::npos);
}

// `diefill plan` on the ring (docs/INTERFACE.md, "Plans"): every grain size's run as `diefill
// scene` sizes it (the default's 16,042 grains and 79,957 pass steps), a predicted time for each,
// the annulus as the narrowest part (5 mm), the sizes with fewer than five grains across it
// marked, and a chosen command. The cache holds the development machine's kernel rate on two idle
// threads (AMD EPYC, 1.55e7 particle-steps per second), so that the plan does not depend on what
// else runs beside the test: measured beside another test, the rate came out 2 to 35 times lower,
// and no run fitted the budget.
TEST(PipelineOwnRuns, PlanPredictsEachGrainSizesRunAndChoosesOne) {
  const fs::path dir = suite_out() / "plan";
  fs::remove_all(dir);
  fs::create_directories(dir / ".cache");
  test::write_text(dir / ".cache" / "throughput.json", nlohmann::json{{pipeline::machine_key(2), 1.55e7}}.dump());
  const test::Run r = test::run_diefill("plan " + bundled_die("ring").string() + " --out " + dir.string() + " --json " +
                                        (dir / "plan.json").string() + " --accuracy 0.02 --budget 10m --threads 2");
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json plan = nlohmann::json::parse(read_text(dir / "plan.json"));
  EXPECT_NEAR(plan["narrowest_tenth_m"].get<double>(), 5e-3, 0.3e-3);
  bool default_size = false;
  for (const auto& level : plan["levels"]) {
    EXPECT_GT(level["predicted_wall_s"].get<double>(), 0);
    EXPECT_EQ(level["affine"].get<bool>(), level["grains_across_narrowest"].get<double>() >= 5);
    if (level["coarse_graining"].get<double>() == 8) {
      default_size = true;
      EXPECT_EQ(level["grains"], 16042);
      EXPECT_EQ(level["pass_steps"], 79957);
    }
  }
  EXPECT_TRUE(default_size);
  ASSERT_FALSE(plan["chosen"].is_null()) << r.output;
  EXPECT_TRUE(plan["chosen"]["command"].get<std::string>().starts_with("diefill run ")) << plan["chosen"].dump();
  EXPECT_LE(plan["chosen"]["predicted_wall_s"].get<double>(), 600);
  EXPECT_GE(plan["machine"]["kernel_particle_steps_per_s"].get<double>(), 1.55e7);
}

// The cache keeps the fastest kernel rate the machine has shown: a measurement slower than the
// kept figure leaves it (and the plan takes the kept one), a faster one replaces it.
TEST(Throughput, TheCacheKeepsTheFastestRateMeasured) {
  const scene::PipelineScene scene = scene::load_pipeline_scene(std::nullopt, {"simulation.threads=2"});
  const double d = scene.powder.grain_diameter();
  const pipeline::GrainSizing grains{d, 0.5 * d, scene.powder.coarse_graining, 0};
  const fs::path cache = suite_out() / "kernel_rate";
  fs::create_directories(cache);
  const auto kept = [&] { return nlohmann::json::parse(read_text(cache / "throughput.json"))[pipeline::machine_key(2)].get<double>(); };
  const auto keep = [&](double rate) { test::write_text(cache / "throughput.json", nlohmann::json{{pipeline::machine_key(2), rate}}.dump()); };
  keep(1e15);  // no machine measures this fast
  EXPECT_EQ(pipeline::kernel_rate(scene, grains, cache), 1e15);
  EXPECT_EQ(kept(), 1e15);
  keep(1);  // nor this slow
  const double measured = pipeline::kernel_rate(scene, grains, cache);
  EXPECT_GT(measured, 1);
  EXPECT_EQ(kept(), measured);
}
