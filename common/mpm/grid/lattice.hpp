#pragma once
/// The background lattice of a scene: a uniform grid of cubic (square in 2D) cells of size h
/// covering the domain. Nodes are numbered 0..cells[a] along each axis a; the solver allocates
/// nodes only in a window around the particles (see grid.hpp).
#include <array>
#include <string>

#include "mpm/core/types.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {

struct Lattice {
  int dim = 3;                        ///< 2 or 3; in 2D the z entries are unused
  Vec3 origin = Vec3::Zero();         ///< position of node (0,0,0) = domain minimum corner, m
  double h = 0;                       ///< cell size, m
  std::array<int, 3> cells{0, 0, 0};  ///< cells along x, y, z (z = 1 in 2D)
  /// Domain maximum corner, m.
  Vec3 max() const {
    Vec3 m = origin;
    for (int a = 0; a < dim; ++a) m[a] += h * cells[a];
    return m;
  }
  long long cell_count() const {
    long long n = 1;
    for (int a = 0; a < dim; ++a) n *= cells[a];
    return n;
  }
};

/// The lattice of a scene: the given domain, or the bodies' bounding box plus padding, with the
/// maximum corner rounded up to whole cells. Throws InputError when the cell size is missing,
/// the domain is empty or would need more than 2^31 cells along an axis.
Lattice make_lattice(const Scene& scene);

}  // namespace mpm
