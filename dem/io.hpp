#pragma once
// Particle files (docs/INTERFACE.md): particles CSV in and out, trajectory CSV, VTU snapshots that
// ParaView reads. SI units throughout.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "dem/state.hpp"

namespace dem {

// Reads `id,x,y,z,vx,vy,vz,wx,wy,wz,radius[,density]` (header required, columns in any order;
// body,qw,qx,qy,qz are accepted and ignored for free spheres, body -1; a clump member throws). Grains get `material`, and
// `default_density` when the file has no density column. Throws InputError naming the file,
// the line and the column for missing columns, unparsable or non-finite values.
//
// With `share` (a split run: every rank reads the file), this rank keeps every share.ranks-th row
// from row share.rank on, the grains share_of would keep, and no rank holds them all; every row is
// checked on every rank, so that a bad one stops all alike.
struct RowShare {
  int rank = 0, ranks = 1;
};
State read_particles_csv(const std::filesystem::path& path, int material, double default_density, RowShare share = {});
// Adds `body,qw,qx,qy,qz` (body index, its orientation; -1 and identity for a free sphere)
// when the state holds clumps. Split over ranks (collective): one file of every rank's grains,
// rank after rank.
void write_particles_csv(const State& state, const std::filesystem::path& path);

// Appends `t,id,x,y,z,vx,vy,vz,wx,wy,wz,fx,fy,fz` rows.
class TrajectoryWriter {
 public:
  // `append`: a resumed run's rows go after the interrupted run's (the header is there).
  TrajectoryWriter(const std::filesystem::path& path, bool append);
  ~TrajectoryWriter();
  void write(const State& state);

 private:
  std::FILE* file_ = nullptr;
};

// VTK XML unstructured grid of points with point data id, radius, velocity, angular_velocity,
// force, body; returns what it wrote. Split over ranks (collective): every rank writes its owned
// grains as a piece beside `path` (NAME_rR.vtu) and rank 0 the index ParaView opens, `path` with
// the extension .pvtu.
std::filesystem::path write_vtu(const State& state, const std::filesystem::path& path);

}  // namespace dem

namespace dem {
// Reads a VTU snapshot written by write_vtu (points and the radius array; the rest ignored).
State read_particles_vtu(const std::filesystem::path& path, int material, double density);
// By extension: .csv or .vtu.
State read_particles(const std::filesystem::path& path, int material, double default_density);
}  // namespace dem
