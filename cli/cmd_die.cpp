// `diefill die NAME -o FILE`: regenerates a bundled die, so dies/ is reproducible.
#include <fmt/core.h>

#include "cli/commands.hpp"
#include "mesh/import.hpp"
#include "mesh/shapes.hpp"

namespace cli {

int run_die(const DieCommand& c) {
  const geometry::TriMesh die = mesh::bundled_die(c.name);
  mesh::write_stl(die, c.output, geometry::LengthUnit::mm, "diefill " + c.name + " cavity, mm");
  fmt::print("wrote {} ({} triangles)\n", c.output.string(), die.triangles.size());
  return 0;
}

}  // namespace cli
