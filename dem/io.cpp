#include "dem/io.hpp"

#include <fmt/core.h>

#include <bit>
#include <charconv>
#include <cstring>
#include <cmath>
#include <fstream>
#include <map>
#include <numeric>
#include <sstream>

#include "core/atomic_file.hpp"
#include "core/base64.hpp"
#include "core/error.hpp"
#include "dem/distributed.hpp"

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

State read_particles_csv(const fs::path& path, int material, double default_density, RowShare share) {
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
  std::size_t rows = 0;
  for (std::size_t number = 2; std::getline(in, line); ++number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const bool mine = rows++ % std::size_t(share.ranks) == std::size_t(share.rank);
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
    if (mine) s.add_sphere(std::int64_t(id), x, radius, density, material, v, w);
  }
  if (rows == 0) throw InputError(path.string(), "", "holds no particles", "Add rows below the header");
  return s;
}

namespace {

// A split state's clumps numbered over all ranks (each rank's after the ranks before it); a
// single process's as they are.
std::int64_t first_body_number(const State& s) {
  if (!s.exchange) return 0;
  const std::vector<double> counts = s.exchange->all_gather({double(s.bodies.size())});
  return std::int64_t(std::accumulate(counts.begin(), counts.begin() + s.exchange->rank(), 0.0));
}

// The owned grains' rows, written to `out` in pieces of about a megabyte.
// `clumps`: the body columns, which a split state writes on every rank when any rank holds a clump.
void write_csv_rows(const State& s, std::ofstream& out, bool header, bool clumps, std::int64_t first_body) {
  std::string text;
  if (header)
    text = clumps ? "id,x,y,z,vx,vy,vz,wx,wy,wz,radius,density,body,qw,qx,qy,qz\n" : "id,x,y,z,vx,vy,vz,wx,wy,wz,radius,density\n";
  for (std::size_t i = 0; i < s.owned(); ++i) {
    const std::int32_t b = s.body[i];
    // A member's density is its grain's, whose mass is the body's.
    const double density = b >= 0 ? s.bodies.mass[std::size_t(b)] / s.bodies.volume[std::size_t(b)]
                                   : s.mass[i] / (4.0 / 3.0 * 3.14159265358979323846 * std::pow(s.radius[i], 3));
    text += fmt::format("{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}",
                        s.id[i], s.x[i].x(), s.x[i].y(), s.x[i].z(), s.v[i].x(), s.v[i].y(), s.v[i].z(), s.w[i].x(),
                        s.w[i].y(), s.w[i].z(), s.radius[i], density);
    if (clumps) {
      const Quat q = b >= 0 ? s.bodies.q[std::size_t(b)] : Quat::Identity();
      text += fmt::format(",{},{:.17g},{:.17g},{:.17g},{:.17g}", b >= 0 ? first_body + b : -1, q.w(), q.x(), q.y(), q.z());
    }
    text += '\n';
    if (text.size() > (1u << 20)) out << text, text.clear();
  }
  out << text;
}

void check_written(const std::ofstream& out, const fs::path& path) {
  if (!out) throw InputError(path.string(), "", "cannot be written", "Check that the output folder is writable and the disk is not full");
}

}  // namespace

// Split over ranks, the ranks append their rows in turn to one file (rank order, each rank's in
// its own order), which rank 0 then moves into place: no rank holds another's grains.
void write_particles_csv(const State& s, const fs::path& path) {
  if (!s.exchange) {
    diefill::PendingFile pending(path);
    {
      std::ofstream out(pending.path(), std::ios::binary);
      write_csv_rows(s, out, true, s.bodies.size() > 0, 0);
      check_written(out, path);
    }
    pending.commit();
    return;
  }
  const std::int64_t first_body = first_body_number(s);
  const bool clumps = s.exchange->sum(std::int64_t(s.bodies.size())) > 0;
  const fs::path partial = fs::path(path).concat(".partial");
  const bool first = s.exchange->rank() == 0;
  run_and_agree(s.exchange.get(), true, [&] {
    s.exchange->in_turn([&] {
      if (first && path.has_parent_path()) fs::create_directories(path.parent_path());
      std::ofstream out(partial, first ? std::ios::binary | std::ios::trunc : std::ios::binary | std::ios::app);
      write_csv_rows(s, out, first, clumps, first_body);
      check_written(out, path);
    });
  });
  run_and_agree(s.exchange.get(), first, [&] { fs::rename(partial, path); });
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

// Base64 of one stream of bytes fed in small pieces, encoded a few megabytes at a time.
class Base64Writer {
 public:
  explicit Base64Writer(std::ostream& out) : out_(out) {}
  void add(const void* data, std::size_t size) {
    pending_.append(static_cast<const char*>(data), size);
    if (pending_.size() >= (std::size_t(3) << 20)) flush(pending_.size() / 3 * 3);
  }
  void finish() { flush(pending_.size()); }

 private:
  void flush(std::size_t bytes) {  // a multiple of 3, or the end: the pieces' codes join as one
    out_ << diefill::base64_encode(pending_.data(), bytes);
    pending_.erase(0, bytes);
  }
  std::ostream& out_;
  std::string pending_;
};

static_assert(sizeof(Vec3) == 3 * sizeof(double), "a Vec3 is written as its three doubles");

// A binary DataArray of `count` values value(i): base64 of a UInt64 byte count and the
// little-endian values (VTK's XML "binary" format): every value exact, with no text conversion
// either way. (Base64's 4/3 leaves it only 12 % smaller than nine-digit ASCII, measured on the
// ring's final state.)
template <typename Value>
void binary_array(std::ostream& out, const char* type, const std::string& name, int components, std::size_t count, Value value) {
  using T = std::decay_t<decltype(value(std::size_t{0}))>;
  const std::uint64_t size = count * sizeof(T);
  // Scalars without NumberOfComponents, as VTK writes them (readers such as meshio then give 1-D arrays).
  const std::string shape = components > 1 ? fmt::format(" NumberOfComponents=\"{}\"", components) : "";
  out << fmt::format("<DataArray type=\"{}\" Name=\"{}\"{} format=\"binary\">\n", type, name, shape);
  Base64Writer encoded(out);
  encoded.add(&size, sizeof size);
  for (std::size_t i = 0; i < count; ++i) {
    const T v = value(i);
    encoded.add(&v, sizeof v);
  }
  encoded.finish();
  out << "\n</DataArray>\n";
}

// The point data of write_vtu, in its order: name, VTK type, components.
struct PointArray {
  const char* name;
  const char* type;
  int components;
};
constexpr PointArray point_arrays[] = {{"id", "Int64", 1},       {"radius", "Float64", 1},           {"velocity", "Float64", 3},
                                       {"angular_velocity", "Float64", 3}, {"force", "Float64", 3}, {"body", "Int64", 1}};

// The owned grains as one VTU file.
void write_vtu_file(const State& s, const fs::path& path) {
  diefill::PendingFile pending(path);
  {
    std::ofstream out(pending.path(), std::ios::binary);
    const std::size_t n = s.owned();
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
           "header_type=\"UInt64\">\n";
    out << fmt::format("<UnstructuredGrid><Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", n, n);
    out << "<Points>\n";
    binary_array(out, "Float64", "Points", 3, n, [&](std::size_t i) { return s.x[i]; });
    out << "</Points>\n<PointData Scalars=\"radius\" Vectors=\"velocity\">\n";
    binary_array(out, "Int64", "id", 1, n, [&](std::size_t i) { return s.id[i]; });
    binary_array(out, "Float64", "radius", 1, n, [&](std::size_t i) { return s.radius[i]; });
    binary_array(out, "Float64", "velocity", 3, n, [&](std::size_t i) { return s.v[i]; });
    binary_array(out, "Float64", "angular_velocity", 3, n, [&](std::size_t i) { return s.w[i]; });
    binary_array(out, "Float64", "force", 3, n, [&](std::size_t i) { return s.f[i]; });
    // A sphere is its own body; a clump is named by its first member.
    binary_array(out, "Int64", "body", 1, n, [&](std::size_t i) {
      const std::int32_t b = s.body[i];
      return s.id[b < 0 ? i : std::size_t(s.bodies.member[std::size_t(s.bodies.member_start[std::size_t(b)])])];
    });
    out << "</PointData>\n<Cells>\n";
    binary_array(out, "Int64", "connectivity", 1, n, [](std::size_t i) { return std::int64_t(i); });
    binary_array(out, "Int64", "offsets", 1, n, [](std::size_t i) { return std::int64_t(i + 1); });
    binary_array(out, "UInt8", "types", 1, n, [](std::size_t) { return std::uint8_t(1); });  // VTK_VERTEX
    out << "</Cells>\n</Piece></UnstructuredGrid>\n</VTKFile>\n";
    check_written(out, path);
  }
  pending.commit();
}

// The index ParaView opens for a split state's pieces.
std::string pvtu_index(const std::vector<std::string>& pieces) {
  std::string out = "<?xml version=\"1.0\"?>\n<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
                    "header_type=\"UInt64\">\n<PUnstructuredGrid GhostLevel=\"0\">\n"
                    "<PPoints><PDataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\"/></PPoints>\n"
                    "<PPointData Scalars=\"radius\" Vectors=\"velocity\">\n";
  for (const PointArray& a : point_arrays)
    out += fmt::format("<PDataArray type=\"{}\" Name=\"{}\"{}/>\n", a.type, a.name,
                       a.components > 1 ? fmt::format(" NumberOfComponents=\"{}\"", a.components) : "");
  out += "</PPointData>\n";
  for (const std::string& piece : pieces) out += fmt::format("<Piece Source=\"{}\"/>\n", piece);
  return out + "</PUnstructuredGrid>\n</VTKFile>\n";
}

}  // namespace

fs::path write_vtu(const State& s, const fs::path& path) {
  if (!s.exchange) {
    write_vtu_file(s, path);
    return path;
  }
  const int rank = s.exchange->rank(), ranks = s.exchange->ranks();
  const auto piece = [&](int r) { return fmt::format("{}_r{}.vtu", path.stem().string(), r); };
  run_and_agree(s.exchange.get(), true, [&] { write_vtu_file(s, path.parent_path() / piece(rank)); });
  fs::path index = path;
  index.replace_extension(".pvtu");
  std::vector<std::string> pieces;
  for (int r = 0; r < ranks; ++r) pieces.push_back(piece(r));
  run_and_agree(s.exchange.get(), rank == 0, [&] { diefill::write_file_atomic(index, pvtu_index(pieces)); });
  return index;
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
