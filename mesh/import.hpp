#pragma once
// Reading a user's CAD mesh through assimp: every format assimp reads, several meshes in one
// file joined into one, duplicate vertices welded, coordinates converted to metres.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "geometry/trimesh.hpp"

namespace mesh {

struct ImportOptions {
  std::optional<geometry::LengthUnit> unit = geometry::LengthUnit::mm;  // unset: guessed from the size (guess_unit), with a warning
};

struct ImportResult {
  geometry::TriMesh mesh;                                // metres
  geometry::LengthUnit unit = geometry::LengthUnit::mm;  // the file's unit, as given or guessed
  bool unit_guessed = false;
  std::string format;                  // file extension as assimp saw it
  int meshes_joined = 0;               // meshes (solids, objects) found in the file
  std::size_t vertices_read = 0;       // before welding
  std::size_t vertices_welded = 0;     // removed as exact duplicates
  std::size_t faces_dropped = 0;       // points and lines, which cannot bound a solid
  std::vector<std::string> warnings;   // also written to the log
};

// Throws diefill::InputError (file, field, remedy) for a missing path, a directory, an empty
// or unreadable file, a file with no triangles, or non-finite coordinates.
ImportResult import_mesh(const std::filesystem::path& path, const ImportOptions& options = {});

// Exact-coordinate weld; returns how many vertices it removed. Keeps triangle order.
std::size_t weld_exact(geometry::TriMesh& mesh);

// Binary STL writer (the format dies/ uses); coordinates written in `unit`.
void write_stl(const geometry::TriMesh& mesh, const std::filesystem::path& path, geometry::LengthUnit unit,
               const std::string& header);
// VTK XML PolyData of the surface in metres, moved by `shift`: what ParaView shows beside grains.
void write_vtp(const geometry::TriMesh& mesh, const std::filesystem::path& path, const geometry::Vec3& shift = geometry::Vec3::Zero());

}  // namespace mesh
