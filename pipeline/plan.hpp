#pragma once
// The first stages of a die fill, before any wall or grain exists: read the die's file once, size
// the grains (coarser when the shoe would need more than powder.max_grains) and plan the shoe's
// path over the die.
#include <filesystem>

#include "dem/motion.hpp"
#include "mesh/die.hpp"
#include "scene/pipeline_scene.hpp"

namespace pipeline {

// The die's file as read: its mesh in metres, its box and the table's height (its highest z).
struct DieSource {
  mesh::DieFile file;
  geometry::Box box;
  double table_z = 0;
};
DieSource read_die(const scene::DieSettings& die, const std::filesystem::path& die_mesh);

// Where the shoe goes: its inner rectangle centred at (x, y_centre) on the table.
struct ShoePlan {
  double length = 0, width = 0;  // inner [m] (width after trimming)
  double x_start = 0, x_end = 0;  // shoe centre at the start and the end of a pass
  double y_centre = 0;
  double t_motion = 0;           // duration of the whole motion [s]
  dem::Motion motion;            // of the shoe's frame (origin at its inner centre, raised by the clearance)
};

// The simulated grains: the scene's, or coarser when the shoe's powder would need too many.
struct GrainSizing {
  double diameter = 0;       // mean [m]
  double r_max = 0;          // largest radius [m]
  double alpha = 0;          // coarse graining actually used
  std::size_t count = 0;     // grains that fill the shoe to shoe.fill_height
};

// Random insertion jams near a third of the volume (random sequential adsorption), so a bed of
// poured density 0.6 needs about twice its height of space; a round fills what space the shoe
// has above the powder already in it, and the powder settles before the next, up to this many.
inline constexpr int max_insertion_rounds = 4;

ShoePlan plan_shoe(const scene::ShoeSettings& shoe, const scene::MotionSettings& motion, const DieSource& die);
GrainSizing size_grains(const scene::PowderSettings& powder, double fill_height, const ShoePlan& shoe, const std::string& die_name);
// The shoe's start raised by the clearance under its walls, now that the grains are sized.
void set_clearance(double clearance, const GrainSizing& grains, double table_z, ShoePlan& shoe);

// The die read, the shoe laid over it and the grains sized for its powder: what a run's size, its
// walls and its preflight follow from.
struct FillLayout {
  DieSource source;
  ShoePlan shoe;
  GrainSizing grains;
};
FillLayout lay_out_fill(const scene::PipelineScene& scene, const std::filesystem::path& die_mesh);

}  // namespace pipeline
