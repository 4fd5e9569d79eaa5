#pragma once
// How far apart a cavity's walls face each other: the widths of its features (an annulus's gap,
// a gear's teeth, a slot), which decide how many grains a feature holds across. Sampled on a
// grid: where the closest wall points of two neighbouring grid points lie on walls that face each
// other (directions to them more than 120° apart), the pair straddles the feature's middle and
// the distance of the two wall points is its width there. The open top is no wall, and a convex
// edge or a corner of the cavity (walls meeting at 90°) is no feature.
#include <vector>

#include "geometry/trimesh.hpp"

namespace mesh {

struct FeatureWidths {
  struct Crossing {
    double width = 0;   // [m] between the two wall points
    double volume = 0;  // [m³] of the cavity the crossing stands for
    geometry::Vec3 a, b;  // the wall points
  };
  std::vector<Crossing> crossings;
  double cavity_volume = 0;  // [m³]

  // The share of the cavity's volume in features no wider than `width`.
  double share_below(double width) const;
  // The narrowest crossing of those (nullptr when there is none).
  const Crossing* narrowest() const;
};

// The cavity (closed, outward; its opening is its faces at `table_z`) sampled every `spacing`.
FeatureWidths feature_widths(const geometry::TriMesh& cavity, double table_z, double spacing);

}  // namespace mesh
