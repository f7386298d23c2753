#pragma once
// Scenes and particle blocks built in code for the solver tests (no parser, no voxeliser).
#include <functional>

#include "mpm/core/columns.hpp"
#include "mpm/grid/lattice.hpp"
#include "mpm/scene/particles.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm::testing {

/// An elastic (or J2) material with a linear EOS.
inline MaterialSpec elastic(double E, double nu, double rho) {
  MaterialSpec m;
  m.name = "m";
  m.density = rho;
  m.youngs_modulus = E;
  m.poisson_ratio = nu;
  return m;
}

/// A scene with one material and free faces, no viscosity, cell size h.
inline Scene scene_with(const MaterialSpec& m, int dim, double h, double end_time) {
  Scene s;
  s.source = "test";
  s.dimension = dim;
  s.materials.push_back(m);
  BodySpec b;
  b.name = "block";
  b.material = 0;
  s.bodies.push_back(b);
  s.grid.cell_size = h;
  s.solver.end_time = end_time;
  s.solver.bulk_linear = s.solver.bulk_quadratic = 0;
  return s;
}

inline Lattice lattice(int dim, const Vec3& origin, double h, std::array<int, 3> cells) {
  Lattice l;
  l.dim = dim;
  l.origin = origin;
  l.h = h;
  l.cells = cells;
  return l;
}

/// n^dim particles per cell in the cells [lo, hi) (global cell indices) of a lattice, with
/// velocity v(x) and density rho; the columns of a model.
template <int D>
ColumnStore block(const Lattice& lat, const IVec<D>& lo, const IVec<D>& hi, int n, double rho,
                  const std::function<Vec<D>(const Vec<D>&)>& v) {
  std::vector<Vec<D>> xs;
  IVec<D> c = lo;
  const double dp = lat.h / n;
  while (true) {
    IVec<D> k = IVec<D>::Zero();
    while (true) {
      Vec<D> x;
      for (int a = 0; a < D; ++a) x[a] = lat.origin[a] + c[a] * lat.h + (k[a] + 0.5) * dp;
      xs.push_back(x);
      int a = 0;
      while (a < D && ++k[a] == n) k[a++] = 0;
      if (a == D) break;
    }
    int a = 0;
    while (a < D && ++c[a] == hi[a]) c[a] = lo[a], ++a;
    if (a == D) break;
  }
  ColumnStore cols;
  cols.add({col::id, ScalarType::U32, 1, "-"});
  cols.add({col::body, ScalarType::U8, 1, "-"});
  cols.add({col::material, ScalarType::U8, 1, "-"});
  cols.add({col::x, ScalarType::F64, D, "m"});
  cols.add({col::v, ScalarType::F64, D, "m/s"});
  cols.add({col::m, ScalarType::F64, 1, "kg"});
  cols.add({col::rho, ScalarType::F64, 1, "kg/m^3"});
  cols.resize(xs.size());
  auto* id = cols.get<std::uint32_t>(col::id);
  auto* x = cols.get<Vec<D>>(col::x);
  auto* vv = cols.get<Vec<D>>(col::v);
  auto* m = cols.get<double>(col::m);
  auto* r = cols.get<double>(col::rho);
  const double vol = std::pow(dp, D);
  for (std::size_t i = 0; i < xs.size(); ++i) {
    id[i] = std::uint32_t(i);
    x[i] = xs[i];
    vv[i] = v(xs[i]);
    m[i] = rho * vol;
    r[i] = rho;
  }
  return cols;
}

}  // namespace mpm::testing
