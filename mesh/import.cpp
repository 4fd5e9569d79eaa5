// The only translation unit that includes assimp.
#include "mesh/import.hpp"

#include <assimp/DefaultLogger.hpp>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/version.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <unordered_map>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "mesh/versions.hpp"
#include "core/log.hpp"

namespace mesh {

namespace fs = std::filesystem;
using diefill::InputError;

namespace {

void check_readable_file(const fs::path& path) {
  std::error_code ec;
  auto status = fs::status(path, ec);
  if (ec || !fs::exists(status))
    throw InputError(path.string(), "", "no such file", "Check the path");
  if (fs::is_directory(status))
    throw InputError(path.string(), "", "is a directory, not a mesh file",
                     "Name a mesh file (STL, OBJ, PLY, OFF, ...); `diefill run` takes folders");
  if (fs::file_size(path, ec) == 0 || ec)
    throw InputError(path.string(), "", "the file is empty", "Export the mesh again");
  std::ifstream probe(path, std::ios::binary);
  if (!probe) throw InputError(path.string(), "", "cannot be read", "Check the file's permissions");
}

// Every mesh instance of the node hierarchy, in the file's world frame: several solids or
// objects in one file become one triangle mesh.
void append_node_meshes(const aiScene& scene, const aiNode& node, const aiMatrix4x4& parent,
                        ImportResult& result) {
  const aiMatrix4x4 transform = parent * node.mTransformation;
  geometry::TriMesh& out = result.mesh;
  for (unsigned n = 0; n < node.mNumMeshes; ++n) {
    const aiMesh& in = *scene.mMeshes[node.mMeshes[n]];
    const int base = int(out.vertices.size());
    for (unsigned v = 0; v < in.mNumVertices; ++v) {
      const aiVector3D p = transform * in.mVertices[v];
      out.vertices.emplace_back(p.x, p.y, p.z);
    }
    result.vertices_read += in.mNumVertices;
    for (unsigned f = 0; f < in.mNumFaces; ++f) {
      const aiFace& face = in.mFaces[f];
      if (face.mNumIndices != 3) {
        ++result.faces_dropped;
        continue;
      }
      out.triangles.push_back({base + int(face.mIndices[0]), base + int(face.mIndices[1]),
                               base + int(face.mIndices[2])});
    }
    ++result.meshes_joined;
  }
  for (unsigned c = 0; c < node.mNumChildren; ++c)
    append_node_meshes(scene, *node.mChildren[c], transform, result);
}

}  // namespace

std::size_t weld_exact(geometry::TriMesh& mesh) {
  struct Key {
    double x, y, z;
    bool operator==(const Key& o) const { return x == o.x && y == o.y && z == o.z; }
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      auto bits = [](double d) {
        if (d == 0.0) d = 0.0;  // -0 and +0 are the same point
        std::uint64_t u;
        std::memcpy(&u, &d, sizeof u);
        return u;
      };
      std::uint64_t h = bits(k.x) * 0x9E3779B97F4A7C15ull;
      h ^= bits(k.y) + 0x7F4A7C159E3779B9ull + (h << 6) + (h >> 2);
      h ^= bits(k.z) + 0x94D049BB133111EBull + (h << 6) + (h >> 2);
      return std::size_t(h);
    }
  };
  std::unordered_map<Key, int, KeyHash> index_of;
  index_of.reserve(mesh.vertices.size());
  std::vector<int> remap(mesh.vertices.size());
  std::vector<geometry::Vec3> kept;
  kept.reserve(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const geometry::Vec3& v = mesh.vertices[i];
    auto [it, inserted] = index_of.try_emplace(Key{v.x(), v.y(), v.z()}, int(kept.size()));
    if (inserted) kept.push_back(v);
    remap[i] = it->second;
  }
  std::size_t removed = mesh.vertices.size() - kept.size();
  mesh.vertices = std::move(kept);
  for (geometry::Triangle& t : mesh.triangles)
    for (int& i : t) i = remap[std::size_t(i)];
  return removed;
}

ImportResult import_mesh(const fs::path& path, const ImportOptions& options) {
  check_readable_file(path);

  Assimp::Importer importer;
  // Lines and points are removed by assimp itself; they cannot bound a solid.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const unsigned flags = aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_ValidateDataStructure;
  const aiScene* scene = importer.ReadFile(path.string(), flags);
  if (scene == nullptr)
    throw InputError(path.string(), "", std::string("not a readable mesh (assimp: ") +
                                            importer.GetErrorString() + ")",
                     "Export it again as STL (binary or ASCII), OBJ, PLY or OFF");

  ImportResult result;
  result.format = path.extension().string();
  if (scene->mRootNode != nullptr) append_node_meshes(*scene, *scene->mRootNode, aiMatrix4x4(), result);
  if (result.mesh.triangles.empty())
    throw InputError(path.string(), "triangles", "the file holds no triangles",
                     "Export the solid as a surface mesh");

  for (const geometry::Vec3& v : result.mesh.vertices)
    if (!v.allFinite())
      throw InputError(path.string(), "vertices",
                       "a vertex coordinate is not a finite number (NaN or infinity)",
                       "Repair or export the mesh again");
  result.unit_guessed = !options.unit;
  const double extent_in_file = geometry::bounding_box(result.mesh).size().maxCoeff();
  result.unit = options.unit ? *options.unit : geometry::guess_unit(extent_in_file);
  const double scale = geometry::metres_per_unit(result.unit);
  for (geometry::Vec3& v : result.mesh.vertices) v *= scale;
  result.vertices_welded = weld_exact(result.mesh);
  if (result.unit_guessed && result.unit != geometry::LengthUnit::mm) {
    std::string msg = fmt::format(
        "{}: no unit given; the mesh is {:.4g} across in the file's numbers, read as {} ({:.4g} mm across: "
        "docs/MESHES.md, \"Units\"). Declare the unit (--units, or die.units in the scene) if that is wrong",
        path.string(), extent_in_file, geometry::unit_name(result.unit), extent_in_file * scale * 1e3);
    diefill::log::write_warning(msg);
    result.warnings.push_back(msg);
  }

  // A die or a grain is between a few tenths of a millimetre and a metre across; outside that
  // range the declared unit is probably wrong.
  const double extent = extent_in_file * scale;
  if (extent < 2e-4 || extent > 2.0) {
    std::string msg = fmt::format(
        "{}: the mesh is {:.4g} {} across ({:.4g} m), implausible for a die or grain; "
        "is `units` right (mm, m or in)?",
        path.string(), extent / scale, geometry::unit_name(result.unit), extent);
    diefill::log::write_warning(msg);
    result.warnings.push_back(msg);
  }
  return result;
}

void write_stl(const geometry::TriMesh& mesh, const fs::path& path, geometry::LengthUnit unit,
               const std::string& header) {
  const double scale = 1.0 / geometry::metres_per_unit(unit);
  std::string bytes(80, ' ');
  std::memcpy(bytes.data(), header.data(), std::min<std::size_t>(80, header.size()));
  auto put = [&bytes](const void* p, std::size_t n) { bytes.append(static_cast<const char*>(p), n); };
  const std::uint32_t count = std::uint32_t(mesh.triangles.size());
  put(&count, 4);
  for (const geometry::Triangle& t : mesh.triangles) {
    const geometry::Vec3& a = mesh.vertices[t[0]];
    const geometry::Vec3& b = mesh.vertices[t[1]];
    const geometry::Vec3& c = mesh.vertices[t[2]];
    geometry::Vec3 n = (b - a).cross(c - a);
    if (n.norm() > 0) n.normalize();
    float values[12] = {float(n.x()), float(n.y()), float(n.z())};
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) values[3 + 3 * k + d] = float(mesh.vertices[t[k]][d] * scale);
    put(values, sizeof values);
    const std::uint16_t attribute = 0;
    put(&attribute, 2);
  }
  diefill::write_file_atomic(path, bytes);
}

void write_vtp(const geometry::TriMesh& mesh, const fs::path& path, const geometry::Vec3& shift) {
  std::string out = fmt::format(
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<PolyData>\n"
      "<Piece NumberOfPoints=\"{}\" NumberOfPolys=\"{}\">\n<Points>\n"
      "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n",
      mesh.vertices.size(), mesh.triangles.size());
  for (const geometry::Vec3& v : mesh.vertices) out += fmt::format("{:.9g} {:.9g} {:.9g}\n", v.x() + shift.x(), v.y() + shift.y(), v.z() + shift.z());
  out += "</DataArray>\n</Points>\n<Polys>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const geometry::Triangle& t : mesh.triangles) out += fmt::format("{} {} {}\n", t[0], t[1], t[2]);
  out += "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (std::size_t k = 1; k <= mesh.triangles.size(); ++k) out += fmt::format("{}\n", 3 * k);
  out += "</DataArray>\n</Polys>\n</Piece>\n</PolyData>\n</VTKFile>\n";
  diefill::write_file_atomic(path, out);
}

}  // namespace mesh

namespace mesh {
std::string assimp_version() {
  return fmt::format("{}.{}.{}", aiGetVersionMajor(), aiGetVersionMinor(), aiGetVersionPatch());
}
}  // namespace mesh
