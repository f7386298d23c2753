// Where the particles put the bodies' flat faces (face_offsets.hpp).
#include "mpm/prep/face_offsets.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

#include "mpm/prep/region.hpp"
#include "mpm/scene/particles.hpp"

namespace mpm {

namespace {

constexpr int kSamples = 16;  // per axis of the face, at the centres of a 16 x 16 division

/// Calls fn(p) at the centres of a 16 x 16 division of the face of the box [lo, hi] at `upper`
/// along axis a, just inside the box (one row in 2D).
template <class Fn>
void for_each_face_sample(const Vec3& lo, const Vec3& hi, int a, bool upper, int dim, Fn&& fn) {
  const double inset = 1e-6 * (hi[a] - lo[a]);
  const int b = (a + 1) % 3, c = (a + 2) % 3;
  const int nb = (dim == 2 && b == 2) ? 1 : kSamples, nc = (dim == 2 && c == 2) ? 1 : kSamples;
  for (int i = 0; i < nb; ++i)
    for (int j = 0; j < nc; ++j) {
      Vec3 p;
      p[a] = upper ? hi[a] - inset : lo[a] + inset;
      p[b] = nb == 1 ? lo[b] : lo[b] + (i + 0.5) / nb * (hi[b] - lo[b]);
      p[c] = nc == 1 ? lo[c] : lo[c] + (j + 0.5) / nc * (hi[c] - lo[c]);
      fn(p);
    }
}

/// True when the face of `region`'s box [lo, hi] at `upper` along axis a is flat: a quarter or
/// more of the sample points just inside it lie in the region.
bool flat_face(const Region& region, const Vec3& lo, const Vec3& hi, int a, bool upper, int dim) {
  if (!(hi[a] - lo[a] > 0)) return false;
  int inside = 0, all = 0;
  for_each_face_sample(lo, hi, a, upper, dim, [&](const Vec3& p) {
    inside += region.contains(p) ? 1 : 0;
    ++all;
  });
  return 4 * inside >= all;
}

/// Calls fn(body, region, box_lo, box_hi, axis, upper, face) for each flat face of a primitive
/// body's bounding box that lies inside the domain (a face the domain cuts off, a symmetry plane
/// through the body or a body reaching out of the domain, is not the body's).
template <class Fn>
void for_each_flat_face(const Scene& scene, const Lattice& lattice, Fn&& fn) {
  const double tol = 1e-9 * lattice.h;
  for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
    const BodySpec& spec = scene.bodies[b];
    if (spec.shape == ShapeKind::Mesh) continue;
    const std::unique_ptr<Region> region = make_region(spec, scene);
    Vec3 box_lo, box_hi;
    region->bounds(box_lo, box_hi);
    for (int a = 0; a < scene.dimension; ++a)
      for (const bool upper : {false, true}) {
        const double face = upper ? box_hi[a] : box_lo[a];
        if (face < lattice.origin[a] - tol || face > lattice.max()[a] + tol) continue;
        if (!flat_face(*region, box_lo, box_hi, a, upper, scene.dimension)) continue;
        fn(b, *region, box_lo, box_hi, a, upper, face);
      }
  }
}

/// The finest grid level whose box holds p (1 outside every box, and on uniform grids).
int level_at(const Scene& scene, const Vec3& p) {
  int level = 1;
  for (const LevelSpec& l : scene.grid.levels) {
    bool inside = true;
    for (int a = 0; a < scene.dimension; ++a)
      inside = inside && p[a] >= l.min[a] && p[a] <= l.max[a];
    if (inside) level = std::max(level, l.level);
  }
  return level;
}

/// The grid levels that hold the face of the body `region` (bounding box [lo, hi]) at `upper`
/// along axis a: the finest level at each sample point of the face inside the body and the
/// domain [dmin, dmax]; in increasing order.
std::vector<int> levels_holding(const Scene& scene, const Region& region, const Vec3& lo,
                                const Vec3& hi, int a, bool upper, const Vec3& dmin,
                                const Vec3& dmax) {
  std::vector<int> levels;
  for_each_face_sample(lo, hi, a, upper, scene.dimension, [&](const Vec3& p) {
    bool in = region.contains(p);
    for (int k = 0; k < scene.dimension; ++k) in = in && p[k] >= dmin[k] && p[k] <= dmax[k];
    const int l = in ? level_at(scene, p) : 0;
    if (l > 0 && std::find(levels.begin(), levels.end(), l) == levels.end()) levels.push_back(l);
  });
  std::sort(levels.begin(), levels.end());
  return levels;
}

}  // namespace

std::vector<FaceOffset> face_offsets(const Scene& scene, const Lattice& lattice,
                                     const ColumnStore& cols) {
  std::vector<FaceOffset> out;
  const int dim = scene.dimension;
  const std::size_t nb = scene.bodies.size();
  const std::size_t n = cols.size();
  const Column* body_col = cols.find("body");
  const Column* x_col = cols.find("x");
  const double* x = x_col ? reinterpret_cast<const double*>(x_col->data()) : nullptr;
  const double* m = cols.get<double>("m");
  const double* rho = cols.get<double>("rho");
  if (!body_col || !x || !m || !rho || n == 0) return out;
  const BodyIds body(body_col);
  // Each body's particles' extent (centre -+ half the spacing), for each spacing it has: the
  // levels of a graded grid fill a face each on its own lattice.
  struct Extent {
    double s;
    std::array<double, 3> lo, hi;
  };
  constexpr double inf = std::numeric_limits<double>::infinity();
  std::vector<std::vector<Extent>> ext(nb);
  for (std::size_t i = 0; i < n; ++i) {
    const int b = body[i];
    if (b < 0 || std::size_t(b) >= nb || !(m[i] > 0) || !(rho[i] > 0)) continue;
    const double* xi = x + i * std::size_t(dim);
    double s;
    if (dim == 3)
      s = std::cbrt(m[i] / rho[i]);
    else if (scene.axisymmetric)
      s = xi[0] > 0 ? std::sqrt(m[i] / (rho[i] * xi[0])) : 0.0;
    else
      s = std::sqrt(m[i] / rho[i]);
    if (!(s > 0)) continue;
    auto g = std::find_if(ext[b].begin(), ext[b].end(),
                          [s](const Extent& e) { return std::abs(e.s - s) <= 1e-6 * s; });
    if (g == ext[b].end()) {
      ext[b].push_back({s, {inf, inf, inf}, {-inf, -inf, -inf}});
      g = ext[b].end() - 1;
    }
    for (int a = 0; a < dim; ++a) {
      g->lo[a] = std::min(g->lo[a], xi[a] - 0.5 * s);
      g->hi[a] = std::max(g->hi[a], xi[a] + 0.5 * s);
    }
  }
  for (std::vector<Extent>& e : ext)  // coarsest first
    std::sort(e.begin(), e.end(), [](const Extent& p, const Extent& q) { return p.s > q.s; });
  for_each_flat_face(
      scene, lattice,
      [&](std::size_t b, const Region&, const Vec3&, const Vec3&, int a, bool upper, double face) {
        for (const Extent& e : ext[b]) {
          const double filled = upper ? e.hi[a] : e.lo[a];
          const double off = std::abs(filled - face);
          // Particles of this spacing that do not reach the face (a level away from it) fill
          // it nowhere; those that do are within half their spacing of it.
          if (off <= 0.01 * e.s || off > 0.5 * e.s * (1 + 1e-6)) continue;
          out.push_back({b, a, upper, face, filled, e.s});
        }
      });
  return out;
}

std::vector<FacePlace> face_places(const Scene& scene, const Lattice& lattice,
                                   const BodyBoxes& boxes) {
  std::vector<FacePlace> out;
  const int dim = scene.dimension;
  const Vec3 dmin = lattice.origin, dmax = lattice.max();
  // Something beyond the face that a body can strike it with or be stopped by.
  auto faces_something = [&](std::size_t b, const Vec3& lo, const Vec3& hi, int a, bool upper,
                             double face) {
    if (scene.boundary.face[std::size_t(2 * a + (upper ? 1 : 0))] != BoundaryType::Free)
      return true;
    for (std::size_t c = 0; c < boxes.lo.size() && c < scene.bodies.size(); ++c) {
      if (c == b) continue;
      bool across = upper ? boxes.hi[c][a] > face : boxes.lo[c][a] < face;
      for (int k = 0; k < dim; ++k)
        if (k != a) across = across && boxes.lo[c][k] < hi[k] && boxes.hi[c][k] > lo[k];
      if (across) return true;
    }
    return false;
  };
  for_each_flat_face(
      scene, lattice,
      [&](std::size_t b, const Region& region, const Vec3& lo, const Vec3& hi, int a, bool upper,
          double face) {
        if (!faces_something(b, lo, hi, a, upper, face)) return;
        for (const int l : levels_holding(scene, region, lo, hi, a, upper, dmin, dmax)) {
          const double h = std::ldexp(lattice.h, 1 - l);
          const double r = (face - lattice.origin[a]) / h;
          const double frac = r - std::floor(r);
          if (frac <= 0.01 || frac >= 0.99) continue;  // on a node plane, to 1% of a cell
          out.push_back({b, a, face, l, h, lattice.origin[a] + std::floor(r) * h});
        }
      });
  return out;
}

std::string describe(const Scene& scene, const FacePlace& f) {
  const char* axis = axis_name(f.axis);
  char cells[64];
  if (!scene.grid.levels.empty())
    std::snprintf(cells, sizeof cells, "level %d's %.4g mm cells", f.level, f.h * 1e3);
  else
    std::snprintf(cells, sizeof cells, "the %.4g mm cells", f.h * 1e3);
  char text[300];
  std::snprintf(text, sizeof text,
                "%s: face %s = %.4g mm lies %.3g mm above the node plane %s = %.4g mm (%.2g of %s)",
                scene.bodies[f.body].name.c_str(), axis, f.face * 1e3, (f.face - f.below) * 1e3,
                axis, f.below * 1e3, (f.face - f.below) / f.h, cells);
  return text;
}

std::string describe(const Scene& scene, const FaceOffset& f) {
  const char* axis = axis_name(f.axis);
  const double off = f.filled - f.face;
  const bool beyond = f.upper ? off > 0 : off < 0;  // the model's body reaches past the face
  char text[300];
  std::snprintf(text, sizeof text,
                "%s: face %s = %.4g mm filled to %.4g mm (%.3g mm %s; particles %.4g mm apart)",
                scene.bodies[f.body].name.c_str(), axis, f.face * 1e3, f.filled * 1e3,
                std::abs(off) * 1e3, beyond ? "beyond it" : "short of it", f.spacing * 1e3);
  return text;
}

}  // namespace mpm
