#pragma once
/// Caliper widths of a planar point set: what a caliper measures on a specimen that is not
/// quite round, turned through every direction. Used for the foot diameter of a Taylor bar,
/// whose footprint on a Cartesian grid is slightly four-fold (the grid's axes and diagonals
/// spread differently), so twice its largest radius overstates the diameter.
#include <cstddef>
#include <vector>

namespace mpm {

struct Calipers {
  double mean = 0;  ///< width averaged over all directions = hull perimeter / pi (Cauchy)
  double min = 0;   ///< narrowest width (across some hull edge)
  double max = 0;   ///< widest width = the hull's diameter
  std::size_t hull_vertices = 0;
};

/// Widths of the convex hull of the points (x[i], y[i]) (CGAL's convex_hull_2): exact for the
/// hull, in O(n log n + h^2) for h hull vertices. Empty input gives zeros.
Calipers caliper_widths(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace mpm
