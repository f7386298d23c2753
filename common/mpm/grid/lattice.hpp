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

/// "x", "y" or "z": the name of axis a (0, 1, 2), for messages.
inline const char* axis_name(int a) {
  return a == 0 ? "x" : a == 1 ? "y" : "z";
}

/// Checks what every lattice of a scene needs: a dimension of 2 or 3 and a positive, finite
/// cell size (m). Throws InputError naming dimension or grid.cell_size.
void check_lattice_scene(const Scene& scene);

/// The lattice of a scene whose domain is given (grid.domain, as in every model's scene), with
/// the maximum corner rounded up to whole cells. Throws InputError when the dimension or the cell
/// size is bad, no domain is given (mpm-prep fits one around the bodies: fit_lattice in
/// prep/region.hpp), the domain is empty, or it would need more than 2^31 cells along an axis or
/// 2^40 in all.
Lattice make_lattice(const Scene& scene);

/// The lattice of the scene's cell size over the box [lo, hi] (m), with the maximum corner
/// rounded up to whole cells (at least one cell along each axis). Throws InputError as
/// make_lattice(scene) does for the dimension, the cell size and the number of cells.
Lattice make_lattice(const Scene& scene, const Vec3& lo, const Vec3& hi);

}  // namespace mpm
