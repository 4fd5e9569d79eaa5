#include "studies/study_kit.hpp"

#include <fmt/core.h>

#include <cmath>

#include "pipeline/pictures.hpp"
#include "dem/step.hpp"
#include "mesh/import.hpp"
#include "mesh/sdf.hpp"
#include "mesh/shapes.hpp"

namespace studies {

namespace fs = std::filesystem;
using dem::Vec3;

Powder powder_of(const scene::PipelineScene& scene) {
  Powder p;
  p.spec = scene::coarse_grained_spec(scene.spec, scene.powder.coarse_graining);
  p.powder = scene::powder_material(scene.spec);
  p.wall = scene::tool_material(scene.spec);
  p.diameter = scene.powder.grain_diameter();
  p.spread = scene.powder.diameter_spread;
  p.density = scene.spec.materials[std::size_t(p.powder)].density;
  p.seed = scene.seed;
  p.source = scene.source;
  return p;
}

dem::MeshWall block_wall(const Vec3& lo, const Vec3& hi, double r_max, int material, const std::string& name) {
  return dem::fixed_mesh_wall(std::make_shared<const geometry::WallField>(mesh::contact_wall_field(mesh::box_solid(lo, hi), r_max)),
                              material, name);
}

std::filesystem::path ring_mesh(const std::filesystem::path& work) {
  const std::filesystem::path ring = work / "ring.stl";
  if (!std::filesystem::exists(ring)) {
    std::filesystem::create_directories(work);
    mesh::write_stl(mesh::bundled_die("ring"), ring, geometry::LengthUnit::mm, "diefill ring die");
  }
  return ring;
}

std::size_t add_grains(dem::State& state, const dem::InsertRegion& region, const Powder& powder, std::size_t count,
                       std::uint64_t seed) {
  dem::InsertRequest request;
  request.count = count;
  request.radius = 0.5 * powder.diameter;
  request.radius_spread = powder.spread;
  request.max_solid_fraction = 0.45;
  request.material = powder.powder;
  request.density = powder.density;
  request.seed = seed;
  request.first_id = std::int64_t(state.size());
  return dem::insert_spheres(state, region, request);
}

pipeline::LoopResult advance(const dem::Model& model, dem::State& state, double until, const std::string& label, pipeline::LoopOptions loop) {
  loop.until = until;
  loop.label = label;
  pipeline::LoopResult result = run_until(model, state, loop);
  if (result.interrupted) throw Interrupted{};
  return result;
}

void forget_wall_contacts(dem::State& state) {
  for (dem::WallSlot& slot : state.wall_slots) slot = dem::WallSlot{};
}

MeanAndError mean_and_error(const std::vector<double>& x) {
  MeanAndError m;
  const double n = double(x.size());
  for (double v : x) m.mean += v / n;
  if (x.size() < 2) return m;
  double ss = 0;
  for (double v : x) ss += (v - m.mean) * (v - m.mean);
  m.error = std::sqrt(ss / (n - 1) / n);
  return m;
}

MeanAndError pooled(const std::vector<MeanAndError>& realisations) {
  std::vector<double> values;
  double fits = 0;
  for (const MeanAndError& r : realisations) values.push_back(r.mean), fits += r.error * r.error;
  const MeanAndError scatter = mean_and_error(values);
  return {scatter.mean, std::max(scatter.error, std::sqrt(fits) / double(realisations.size()))};
}

LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y) {
  LineFit fit;
  fit.points = x.size();
  const double n = double(x.size());
  if (x.size() < 2) return fit;
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < x.size(); ++i) mx += x[i], my += y[i];
  mx /= n, my /= n;
  double sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) sxx += (x[i] - mx) * (x[i] - mx), sxy += (x[i] - mx) * (y[i] - my);
  if (sxx <= 0) return fit;
  fit.slope = sxy / sxx;
  fit.intercept = my - fit.slope * mx;
  if (x.size() > 2) {
    double ssr = 0;
    for (std::size_t i = 0; i < x.size(); ++i) ssr += std::pow(y[i] - fit.intercept - fit.slope * x[i], 2);
    const double variance = ssr / (n - 2);
    fit.slope_error = std::sqrt(variance / sxx);
    fit.intercept_error = std::sqrt(variance * (1 / n + mx * mx / sxx));
  }
  return fit;
}

Output::Output(const fs::path& root, const std::string& name)
    : name_(name), directory_(root / name), work_(root / name / "runs"), staging_(root / name) {}

void Output::table(const std::string& file, const std::vector<std::string>& columns,
                   const std::vector<std::vector<nlohmann::json>>& rows) {
  std::string text;
  for (std::size_t c = 0; c < columns.size(); ++c) text += (c ? "," : "") + columns[c];
  text += "\n";
  for (const auto& row : rows) {
    for (std::size_t c = 0; c < row.size(); ++c) {
      // Numbers in full precision; text quoted where it holds a comma or a quote (RFC 4180):
      // labels such as "√2 coarser, stiffness / 10" do.
      text += c ? "," : "";
      if (!row[c].is_string()) {
        text += row[c].dump();
        continue;
      }
      const std::string cell = row[c].get<std::string>();
      if (cell.find_first_of(",\"\n") == std::string::npos) {
        text += cell;
        continue;
      }
      text += '"';
      for (char ch : cell) text += ch == '"' ? std::string("\"\"") : std::string(1, ch);
      text += '"';
    }
    text += "\n";
  }
  diefill::write_file_atomic(staging_ / file, text);
}

void Output::chart(Chart chart) {
  nlohmann::json series = nlohmann::json::array();
  for (const Series& s : chart.series)
    series.push_back({{"label", s.label}, {"x", s.x}, {"y", s.y}, {"error", s.error}, {"style", s.style}});
  charts_.push_back({{"file", chart.file},
                     {"title", chart.title},
                     {"x_label", chart.x_label},
                     {"y_label", chart.y_label},
                     {"log_x", chart.log_x},
                     {"log_y", chart.log_y},
                     {"y_ticks", chart.y_ticks},
                     {"series", series}});
}

void Output::commit() {
  nlohmann::json document = results;
  document["charts"] = charts_;
  const fs::path json = staging_ / (name_ + ".json");
  diefill::write_file_atomic(json, document.dump(2) + "\n");
  pipeline::draw_pictures({"study", json.string()});
  staging_.commit();
}

}  // namespace studies
