#include "dem/io.hpp"

#include <fmt/core.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "core/atomic_file.hpp"
#include "core/error.hpp"

namespace dem {

namespace fs = std::filesystem;
using diefill::InputError;

namespace {

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    std::string_view cell = line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
    while (!cell.empty() && (cell.front() == ' ' || cell.front() == '\t')) cell.remove_prefix(1);
    while (!cell.empty() && (cell.back() == ' ' || cell.back() == '\t' || cell.back() == '\r')) cell.remove_suffix(1);
    out.push_back(cell);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return out;
}

}  // namespace

State read_particles_csv(const fs::path& path, int material, double default_density) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string(), "", "cannot be read", "Check the path");
  std::string header;
  if (!std::getline(in, header))
    throw InputError(path.string(), "header", "the file is empty", "Write the header id,x,y,z,vx,vy,vz,wx,wy,wz,radius[,density]");
  std::map<std::string, std::size_t, std::less<>> column;
  const auto names = split(header);
  for (std::size_t c = 0; c < names.size(); ++c) column[std::string(names[c])] = c;
  static const char* required[] = {"id", "x", "y", "z", "vx", "vy", "vz", "wx", "wy", "wz", "radius"};
  for (const char* name : required)
    if (!column.count(name))
      throw InputError(path.string(), std::string("column ") + name, "is missing from the header",
                       "The header must name id,x,y,z,vx,vy,vz,wx,wy,wz,radius (density optional)");
  const bool has_density = column.count("density") > 0;
  const bool has_body = column.count("body") > 0;
  State s;
  std::string line;
  for (std::size_t number = 2; std::getline(in, line); ++number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const auto cells = split(line);
    auto value = [&](const char* name) {
      const std::size_t c = column.at(name);
      double v = 0;
      if (c >= cells.size())
        throw InputError(path.string(), fmt::format("line {}, column {}", number, name), "the value is missing",
                         "Give every row a value for every column");
      const auto [end, err] = std::from_chars(cells[c].data(), cells[c].data() + cells[c].size(), v);
      if (err != std::errc() || end != cells[c].data() + cells[c].size() || !std::isfinite(v))
        throw InputError(path.string(), fmt::format("line {}, column {}", number, name),
                         fmt::format("'{}' is not a finite number", cells[c]), "Correct the value");
      return v;
    };
    // A member's place in its clump (the template's offsets, the grain's mass and inertia) is
    // not in the file: refuse rather than read the clump as loose spheres.
    if (has_body && value("body") >= 0)
      throw InputError(path.string(), fmt::format("line {}, column body", number),
                       "names a clump member; clumps cannot be read from a particles CSV",
                       "Resume a clump run from its checkpoint, or insert the clumps from their template");
    const double id = value("id");
    const Vec3 x(value("x"), value("y"), value("z")), v(value("vx"), value("vy"), value("vz")),
        w(value("wx"), value("wy"), value("wz"));
    const double radius = value("radius");
    if (!(radius > 0))
      throw InputError(path.string(), fmt::format("line {}, column radius", number), "must be positive", "Correct the value");
    const double density = has_density ? value("density") : default_density;
    if (has_density && !(density > 0))
      throw InputError(path.string(), fmt::format("line {}, column density", number), "must be positive", "Correct the value");
    if (!has_density && !(density > 0))
      throw InputError(path.string(), "column density", "is missing and no material density is given",
                       "Add a density column, or name the material (scene) or pass --material-density");
    s.add_sphere(std::int64_t(id), x, radius, density, material, v, w);
  }
  if (s.size() == 0) throw InputError(path.string(), "", "holds no particles", "Add rows below the header");
  return s;
}

void write_particles_csv(const State& s, const fs::path& path) {
  const bool clumps = s.bodies.size() > 0;
  std::string out = clumps ? "id,x,y,z,vx,vy,vz,wx,wy,wz,radius,density,body,qw,qx,qy,qz\n"
                           : "id,x,y,z,vx,vy,vz,wx,wy,wz,radius,density\n";
  for (std::size_t i = 0; i < s.size(); ++i) {
    const std::int32_t b = s.body[i];
    // A member's density is its grain's, whose mass is the body's.
    const double density = b >= 0 ? s.bodies.mass[std::size_t(b)] / s.bodies.volume[std::size_t(b)]
                                   : s.mass[i] / (4.0 / 3.0 * 3.14159265358979323846 * std::pow(s.radius[i], 3));
    out += fmt::format("{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}",
                       s.id[i], s.x[i].x(), s.x[i].y(), s.x[i].z(), s.v[i].x(), s.v[i].y(), s.v[i].z(), s.w[i].x(),
                       s.w[i].y(), s.w[i].z(), s.radius[i], density);
    if (clumps) {
      const Quat q = b >= 0 ? s.bodies.q[std::size_t(b)] : Quat::Identity();
      out += fmt::format(",{},{:.17g},{:.17g},{:.17g},{:.17g}", b, q.w(), q.x(), q.y(), q.z());
    }
    out += '\n';
  }
  diefill::write_file_atomic(path, out);
}

TrajectoryWriter::TrajectoryWriter(const fs::path& path) {
  if (path.has_parent_path()) fs::create_directories(path.parent_path());
  file_ = std::fopen(path.c_str(), "w");
  if (!file_) throw InputError(path.string(), "", "cannot be written", "Check the output folder");
  std::fputs("t,id,x,y,z,vx,vy,vz,wx,wy,wz,fx,fy,fz\n", file_);
}

TrajectoryWriter::~TrajectoryWriter() {
  if (file_) std::fclose(file_);
}

void TrajectoryWriter::write(const State& s) {
  for (std::size_t i = 0; i < s.size(); ++i)
    fmt::print(file_, "{:.9g},{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n",
               s.time, s.id[i], s.x[i].x(), s.x[i].y(), s.x[i].z(), s.v[i].x(), s.v[i].y(), s.v[i].z(),
               s.w[i].x(), s.w[i].y(), s.w[i].z(), s.f[i].x(), s.f[i].y(), s.f[i].z());
}

void write_vtu(const State& s, const fs::path& path) {
  std::string out;
  out += "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n";
  out += fmt::format("<UnstructuredGrid><Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", s.size(), s.size());
  auto vectors = [&](const char* name, const Array<Vec3>& a) {
    out += fmt::format("<DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"3\" format=\"ascii\">\n", name);
    for (const Vec3& v : a) out += fmt::format("{:.9g} {:.9g} {:.9g}\n", v.x(), v.y(), v.z());
    out += "</DataArray>\n";
  };
  out += "<Points>\n";
  vectors("Points", s.x);
  out += "</Points>\n<PointData Scalars=\"radius\" Vectors=\"velocity\">\n";
  out += "<DataArray type=\"Int64\" Name=\"id\" format=\"ascii\">\n";
  for (auto id : s.id) out += fmt::format("{}\n", id);
  out += "</DataArray>\n<DataArray type=\"Float64\" Name=\"radius\" format=\"ascii\">\n";
  for (double r : s.radius) out += fmt::format("{:.9g}\n", r);
  out += "</DataArray>\n";
  vectors("velocity", s.v);
  vectors("angular_velocity", s.w);
  vectors("force", s.f);
  out += "<DataArray type=\"Int64\" Name=\"body\" format=\"ascii\">\n";
  // A sphere is its own body; a clump is named by its first member.
  for (std::size_t i = 0; i < s.size(); ++i) {
    const std::int32_t b = s.body[i];
    const std::size_t named = b < 0 ? i : std::size_t(s.bodies.member[std::size_t(s.bodies.member_start[std::size_t(b)])]);
    out += fmt::format("{}\n", s.id[named]);
  }
  out += "</DataArray>\n</PointData>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (std::size_t i = 0; i < s.size(); ++i) out += fmt::format("{}\n", i);
  out += "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (std::size_t i = 0; i < s.size(); ++i) out += fmt::format("{}\n", i + 1);
  out += "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (std::size_t i = 0; i < s.size(); ++i) out += "1\n";  // VTK_VERTEX
  out += "</DataArray>\n</Cells>\n</Piece></UnstructuredGrid>\n</VTKFile>\n";
  diefill::write_file_atomic(path, out);
}

}  // namespace dem

namespace dem {

State read_particles_vtu(const fs::path& path, int material, double density) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string(), "", "cannot be read", "Check the path");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto array = [&](const std::string& name) {
    const std::size_t at = text.find("Name=\"" + name + "\"");
    if (at == std::string::npos)
      throw InputError(path.string(), "DataArray " + name, "is missing", "Give a VTU snapshot diefill wrote");
    const std::size_t begin = text.find('>', at) + 1, end = text.find("</DataArray>", begin);
    std::vector<double> values;
    std::istringstream numbers(text.substr(begin, end - begin));
    for (double v; numbers >> v;) {
      if (!std::isfinite(v)) throw InputError(path.string(), "DataArray " + name, "holds a non-finite value", "Correct the file");
      values.push_back(v);
    }
    return values;
  };
  const std::vector<double> points = array("Points"), radius = array("radius"), ids = array("id");
  if (points.size() != 3 * radius.size() || ids.size() != radius.size() || radius.empty())
    throw InputError(path.string(), "DataArray", "the arrays do not match in length", "Give a VTU snapshot diefill wrote");
  State s;
  for (std::size_t i = 0; i < radius.size(); ++i)
    s.add_sphere(std::int64_t(ids[i]), Vec3(points[3 * i], points[3 * i + 1], points[3 * i + 2]), radius[i], density, material);
  return s;
}

State read_particles(const fs::path& path, int material, double default_density) {
  if (path.extension() == ".vtu") return read_particles_vtu(path, material, default_density);
  return read_particles_csv(path, material, default_density);
}

}  // namespace dem
