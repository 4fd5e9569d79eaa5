#pragma once
// Exact volume of the intersection of a sphere and an axis-aligned box: the basis of binning
// grain volume into voxels without losing or inventing any.
namespace post {

// Volume of {|p - c| <= r} ∩ [lo, hi] [m³], with the box given relative to the sphere's centre
// (lo, hi arrays of 3). The disk-rectangle area of each slice is closed-form (inclusion-exclusion
// of disk-quadrant areas); the slices are integrated by Gauss-Legendre quadrature on intervals
// split where the slice's circle meets the box's edges and corners, so that each piece is smooth.
// Relative accuracy better than 1e-9 of the sphere's volume (tests/test_density.cpp).
double sphere_box_volume(double r, const double lo[3], const double hi[3]);

// Area of the disk of radius rho (centred at the origin) within the rectangle [x0,x1]x[y0,y1].
double disk_rectangle_area(double rho, double x0, double x1, double y0, double y1);

}  // namespace post
