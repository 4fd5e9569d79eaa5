#include "dem/io.hpp"

#include <fmt/core.h>

#include <bit>
#include <charconv>
#include <cstring>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "core/atomic_file.hpp"
#include "core/base64.hpp"
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

TrajectoryWriter::TrajectoryWriter(const fs::path& path, bool append) {
  if (path.has_parent_path()) fs::create_directories(path.parent_path());
  const bool header = !append || !fs::exists(path);
  file_ = std::fopen(path.c_str(), append ? "a" : "w");
  if (!file_) throw InputError(path.string(), "", "cannot be written", "Check the output folder");
  if (header) std::fputs("t,id,x,y,z,vx,vy,vz,wx,wy,wz,fx,fy,fz\n", file_);
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

namespace {

static_assert(std::endian::native == std::endian::little, "the VTU's binary arrays are written as the machine holds them");

// A binary DataArray: base64 of a UInt64 byte count and the little-endian values (VTK's XML
// "binary" format): every value exact, with no text conversion either way. (Base64's 4/3 leaves
// it only 12 % smaller than nine-digit ASCII, measured on the ring's final state.)
template <typename T>
void binary_array(std::string& out, const char* type, const std::string& name, int components, const std::vector<T>& values) {
  std::vector<std::uint8_t> bytes(sizeof(std::uint64_t) + values.size() * sizeof(T));
  const std::uint64_t size = values.size() * sizeof(T);
  std::memcpy(bytes.data(), &size, sizeof size);
  if (!values.empty()) std::memcpy(bytes.data() + sizeof size, values.data(), size);
  // Scalars without NumberOfComponents, as VTK writes them (readers such as meshio then give 1-D arrays).
  const std::string shape = components > 1 ? fmt::format(" NumberOfComponents=\"{}\"", components) : "";
  out += fmt::format("<DataArray type=\"{}\" Name=\"{}\"{} format=\"binary\">\n", type, name, shape);
  out += diefill::base64_encode(bytes.data(), bytes.size());
  out += "\n</DataArray>\n";
}

std::vector<double> flattened(const Array<Vec3>& a) {
  std::vector<double> out;
  out.reserve(3 * a.size());
  for (const Vec3& v : a) out.insert(out.end(), {v.x(), v.y(), v.z()});
  return out;
}

}  // namespace

void write_vtu(const State& s, const fs::path& path) {
  std::string out;
  out += "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
         "header_type=\"UInt64\">\n";
  out += fmt::format("<UnstructuredGrid><Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", s.size(), s.size());
  out += "<Points>\n";
  binary_array(out, "Float64", "Points", 3, flattened(s.x));
  out += "</Points>\n<PointData Scalars=\"radius\" Vectors=\"velocity\">\n";
  binary_array(out, "Int64", "id", 1, std::vector<std::int64_t>(s.id.begin(), s.id.end()));
  binary_array(out, "Float64", "radius", 1, std::vector<double>(s.radius.begin(), s.radius.end()));
  binary_array(out, "Float64", "velocity", 3, flattened(s.v));
  binary_array(out, "Float64", "angular_velocity", 3, flattened(s.w));
  binary_array(out, "Float64", "force", 3, flattened(s.f));
  // A sphere is its own body; a clump is named by its first member.
  std::vector<std::int64_t> body(s.size()), connectivity(s.size()), offsets(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    const std::int32_t b = s.body[i];
    const std::size_t named = b < 0 ? i : std::size_t(s.bodies.member[std::size_t(s.bodies.member_start[std::size_t(b)])]);
    body[i] = s.id[named];
    connectivity[i] = std::int64_t(i);
    offsets[i] = std::int64_t(i + 1);
  }
  binary_array(out, "Int64", "body", 1, body);
  out += "</PointData>\n<Cells>\n";
  binary_array(out, "Int64", "connectivity", 1, connectivity);
  binary_array(out, "Int64", "offsets", 1, offsets);
  binary_array(out, "UInt8", "types", 1, std::vector<std::uint8_t>(s.size(), 1));  // VTK_VERTEX
  out += "</Cells>\n</Piece></UnstructuredGrid>\n</VTKFile>\n";
  diefill::write_file_atomic(path, out);
}

}  // namespace dem

namespace dem {

State read_particles_vtu(const fs::path& path, int material, double density) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string(), "", "cannot be read", "Check the path");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // The byte count before each binary array: UInt32 unless the file says UInt64 (VTK's rule).
  const std::size_t count_bytes = text.find("header_type=\"UInt64\"") != std::string::npos ? 8 : 4;
  auto array = [&](const std::string& name) {
    const std::size_t at = text.find("Name=\"" + name + "\"");
    if (at == std::string::npos)
      throw InputError(path.string(), "DataArray " + name, "is missing", "Give a VTU snapshot diefill wrote");
    const std::size_t tag = text.rfind('<', at), begin = text.find('>', at) + 1, end = text.find("</DataArray>", begin);
    const std::string attributes = text.substr(tag, begin - tag);
    std::vector<double> values;
    if (attributes.find("format=\"binary\"") != std::string::npos) {
      std::vector<std::uint8_t> bytes;
      const bool integers = attributes.find("type=\"Int64\"") != std::string::npos;
      if (!diefill::base64_decode(std::string_view(text).substr(begin, end - begin), bytes) || bytes.size() < count_bytes ||
          (bytes.size() - count_bytes) % 8 != 0 || (!integers && attributes.find("type=\"Float64\"") == std::string::npos))
        throw InputError(path.string(), "DataArray " + name, "is not a binary Float64 or Int64 array diefill can read",
                         "Give a VTU snapshot diefill wrote");
      for (std::size_t b = count_bytes; b < bytes.size(); b += 8) {
        double v;
        if (integers) {
          std::int64_t n;
          std::memcpy(&n, bytes.data() + b, 8);
          v = double(n);
        } else {
          std::memcpy(&v, bytes.data() + b, 8);
        }
        values.push_back(v);
      }
    } else {
      std::istringstream numbers(text.substr(begin, end - begin));
      for (double v; numbers >> v;) values.push_back(v);
    }
    for (double v : values)
      if (!std::isfinite(v)) throw InputError(path.string(), "DataArray " + name, "holds a non-finite value", "Correct the file");
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
