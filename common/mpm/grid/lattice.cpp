// The background lattice of a scene: its domain in whole cells (lattice.hpp).
#include "mpm/grid/lattice.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <string>

#include "mpm/core/error.hpp"
#include "mpm/core/units.hpp"

namespace mpm {

void check_lattice_scene(const Scene& scene) {
  const GridSpec& g = scene.grid;
  const int dim = scene.dimension;
  if (dim != 2 && dim != 3)
    throw InputError(where(scene.source, 0, "dimension"),
                     "the dimension must be 2 or 3 (got " + std::to_string(dim) + ")");
  const double h = g.cell_size;
  if (!(h > 0) || !std::isfinite(h))
    throw InputError(where(scene.source, g.loc.line, "grid.cell_size"),
                     "the cell size must be a positive length in m (got " + format_g6(h) + ")");
}

Lattice make_lattice(const Scene& scene) {
  const GridSpec& g = scene.grid;
  const int dim = scene.dimension;
  check_lattice_scene(scene);
  if (!g.domain_given)
    throw InputError(where(scene.source, g.loc.line, "grid.domain"),
                     "the scene gives no domain (mpm-prep fits one around the bodies and writes "
                     "it into the model's scene)");
  const Vec3 lo = g.domain_min, hi = g.domain_max;
  for (int a = 0; a < dim; ++a)
    if (!std::isfinite(lo[a]) || !std::isfinite(hi[a]) || !(hi[a] > lo[a]))
      throw InputError(where(scene.source, g.loc.line, "grid.domain"),
                       std::string("the domain is empty along ") + axis_name(a) + " (from " +
                           format_g6(lo[a]) + " m to " + format_g6(hi[a]) + " m)");
  return make_lattice(scene, lo, hi);
}

Lattice make_lattice(const Scene& scene, const Vec3& lo, const Vec3& hi) {
  check_lattice_scene(scene);
  const GridSpec& g = scene.grid;
  const int dim = scene.dimension;
  const double h = g.cell_size;
  Lattice lat;
  lat.dim = dim;
  lat.h = h;
  lat.origin = lo;
  if (dim == 2) lat.origin.z() = 0;
  double total = 1;
  for (int a = 0; a < dim; ++a) {
    const double n = std::max(1.0, std::ceil((hi[a] - lo[a]) / h - 1e-9));
    if (n > double(INT_MAX))
      throw InputError(where(scene.source, g.loc.line, "grid.cell_size"),
                       "the domain would need " + format_count(n) + " cells along " + axis_name(a) +
                           "; enlarge grid.cell_size or shrink the domain");
    lat.cells[a] = static_cast<int>(n);
    total *= n;
  }
  if (dim == 2) lat.cells[2] = 1;
  if (total > std::ldexp(1.0, 40))
    throw InputError(where(scene.source, g.loc.line, "grid.cell_size"),
                     "the domain would need " + format_count(total) +
                         " cells; enlarge grid.cell_size or shrink the domain");
  return lat;
}

}  // namespace mpm
