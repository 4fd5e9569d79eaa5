#pragma once
// Reproducible geometry made by the program itself: the bundled dies (cavity meshes, top face
// on the die table at z = 0) and simple test solids.
#include "geometry/trimesh.hpp"

namespace mesh {

// Segments a circle of `radius` needs so that no chord strays more than `chord_error` from it,
// rounded up to a multiple of 8 so that the mesh is mirror-symmetric about the x and y axes.
int circle_segments(double radius, double chord_error);

// Annular (or, with inner_diameter = 0, cylindrical) cavity: top face at z = 0, floor at
// z = -depth, outward-oriented, closed. Lengths in metres.
geometry::TriMesh ring_cavity(double outer_diameter, double inner_diameter, double depth, double chord_error);

// Axis-aligned box [lo, hi], outward-oriented, two triangles a face.
geometry::TriMesh box_solid(const geometry::Vec3& lo, const geometry::Vec3& hi);

// A solid of revolution about the z axis: the closed profile polygon (r > 0, z), counter-clockwise
// in the (r, z) plane, turned through `segments` steps. Outward-oriented, closed.
geometry::TriMesh revolved_solid(const std::vector<std::array<double, 2>>& profile, int segments);

// A feeding shoe: four walls of `thickness` around an inner rectangle (x along the motion,
// y across), from z = 0 to `height`, open at the bottom and the top. Outward-oriented, closed;
// the inner rectangle is centred on the origin.
geometry::TriMesh shoe_solid(double inner_length, double inner_width, double height, double thickness);

// The bundled dies by name; throws InputError for other names. "ring" and "disc" are kept in
// dies/ (bundled_die_names). "gear" and "slot" have sharp features between close cavity features,
// made as a CAD tool extrudes a profile (fans of sliver triangles from the axis, full-height side
// quads): a spur gear of 24 involute teeth, module 1.2 mm, 8 mm deep; a slot 1.2 mm wide, 10 mm
// long, 8 mm deep; "spline", a hub Ø24 mm around a splined core rod (the part's splined bore,
// ISO 14 straight-sided 6 x 11 x 14, keys 3 mm wide), 8 mm deep.
geometry::TriMesh bundled_die(const std::string& name);
std::vector<std::string> bundled_die_names();
std::vector<std::string> generated_die_names();  // every name bundled_die takes

// Largest distance between a circle and its inscribed polygon of `segments` sides.
double chord_error(double radius, int segments);

}  // namespace mesh
