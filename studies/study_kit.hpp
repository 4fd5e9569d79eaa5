#pragma once
// What every study (`diefill study NAME`) shares: the powder of the pipeline's scene, walls made
// of blocks, the stepping loop, straight-line fits with their standard errors, and the outputs:
// CSV tables, one NAME.json with the results and the data of every chart, and the PNG charts
// drawn from it, all appearing together in out/studies/NAME or not at all.
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scene/pipeline_scene.hpp"
#include "pipeline/run_loop.hpp"
#include "core/atomic_file.hpp"
#include "dem/insert.hpp"
#include "dem/model.hpp"
#include "dem/state.hpp"

namespace studies {

// Ctrl-C inside a study: nothing is written, the command exits 130.
struct Interrupted {};

// The scene's powder and wall materials and contact laws, in a spec without walls.
struct Powder {
  dem::ModelSpec spec;
  int powder = 0, wall = 0;  // material indices
  double diameter = 0;       // mean simulated grain diameter [m]
  double spread = 0;         // relative half-width of the size distribution
  double density = 0;        // of the grains' material [kg/m³]
  std::uint64_t seed = 1;
  std::string source;        // the scene, for messages
  double r_max() const { return 0.5 * diameter * (1 + spread); }
};
Powder powder_of(const scene::PipelineScene& scene);

// An axis-aligned solid block [lo, hi] as a wall at rest.
dem::MeshWall block_wall(const dem::Vec3& lo, const dem::Vec3& hi, double r_max, int material, const std::string& name);

// The bundled ring die (annulus from Ø10 to Ø20 mm, 10 mm deep), written once into `work`.
inline constexpr double ring_inner_radius = 5e-3, ring_outer_radius = 10e-3, ring_depth = 10e-3;  // [m]
std::filesystem::path ring_mesh(const std::filesystem::path& work);

// Drops up to `count` of the powder's grains, clear of each other and of the grains present,
// into `region` (loosely: below 0.45 solid fraction of its box); returns how many fitted.
std::size_t add_grains(dem::State& state, const dem::InsertRegion& region, const Powder& powder, std::size_t count,
                       std::uint64_t seed);

// Steps to `until` [s] with the label, outputs and early end of `loop`; throws Interrupted on
// Ctrl-C and StabilityError on a failed check.
pipeline::LoopResult advance(const dem::Model& model, dem::State& state, double until, const std::string& label, pipeline::LoopOptions loop = {});

// Forgets every grain-wall contact: for a scene whose walls change (a gate removed), so that no
// history is carried over to a wall that now has another index.
void forget_wall_contacts(dem::State& state);

// Total mass of the grains for which `counts` holds [kg].
template <class Predicate>
double mass_where(const dem::State& s, Predicate counts) {
  double m = 0;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (counts(i)) m += s.mass[i];
  return m;
}

// Least squares y = intercept + slope x, with standard errors from the residuals.
struct LineFit {
  double slope = 0, intercept = 0, slope_error = 0, intercept_error = 0;
  std::size_t points = 0;
};
LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y);

// The mean of repeated measurements and its standard error (zero for one).
struct MeanAndError {
  double mean = 0, error = 0;
};
MeanAndError mean_and_error(const std::vector<double>& x);
// Realisations of one experiment (beds of other seeds), each a value with its own standard
// error: their mean, with the larger of the realisations' scatter and their own errors as its
// error. One realisation's fit error hides the seed-to-seed scatter (repose heaps 1.6 mm:
// fit errors 0.6-3°, the same powder's heaps 21.4-26.5° over six seeds), and two or three
// realisations' scatter may by chance be smaller than their fits'.
MeanAndError pooled(const std::vector<MeanAndError>& realisations);

// One chart for postprocess/plots.py: series of points (with optional error bars) or lines.
struct Series {
  std::string label;
  std::vector<double> x, y, error;
  std::string style = "points";  // "points" or "line"
};
struct Chart {
  Chart(std::string file_name, std::string chart_title, std::string x, std::string y)
      : file(std::move(file_name)), title(std::move(chart_title)), x_label(std::move(x)), y_label(std::move(y)) {}
  std::string file;  // PNG name
  std::string title, x_label, y_label;
  std::vector<Series> series;
  bool log_x = false, log_y = false;
  std::vector<std::string> y_ticks;  // categorical rows, y = 0, 1, ...
};

// The study's outputs, staged in out/studies/NAME until commit().
class Output {
 public:
  Output(const std::filesystem::path& root, const std::string& name);
  const std::filesystem::path& work() const { return work_; }  // scratch runs, kept beside
  void table(const std::string& file, const std::vector<std::string>& columns,
             const std::vector<std::vector<nlohmann::json>>& rows);
  void chart(Chart chart);
  nlohmann::json results;
  // Writes NAME.json, draws the charts and moves everything into place.
  void commit();
  const std::filesystem::path& directory() const { return directory_; }

 private:
  std::string name_;
  std::filesystem::path directory_, work_;
  diefill::StagingFolder staging_;
  nlohmann::json charts_ = nlohmann::json::array();
};

}  // namespace studies
