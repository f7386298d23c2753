// Where the particles put the bodies' flat faces (face_offsets.hpp).
#include "mpm/prep/face_offsets.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "mpm/prep/region.hpp"
#include "mpm/scene/particles.hpp"

namespace mpm {

namespace {

constexpr int kSamples = 16;  // per axis of the face, at the centres of a 16 x 16 division

/// True when the face of `region`'s box [lo, hi] at `upper` along axis a is flat: a quarter or
/// more of the sample points just inside it lie in the region.
bool flat_face(const Region& region, const Vec3& lo, const Vec3& hi, int a, bool upper, int dim) {
  const double extent = hi[a] - lo[a];
  if (!(extent > 0)) return false;
  const double inset = 1e-6 * extent;
  const int b = (a + 1) % 3, c = (a + 2) % 3;
  const int nb = (dim == 2 && b == 2) ? 1 : kSamples, nc = (dim == 2 && c == 2) ? 1 : kSamples;
  int inside = 0;
  for (int i = 0; i < nb; ++i)
    for (int j = 0; j < nc; ++j) {
      Vec3 p;
      p[a] = upper ? hi[a] - inset : lo[a] + inset;
      p[b] = nb == 1 ? lo[b] : lo[b] + (i + 0.5) / nb * (hi[b] - lo[b]);
      p[c] = nc == 1 ? lo[c] : lo[c] + (j + 0.5) / nc * (hi[c] - lo[c]);
      inside += region.contains(p) ? 1 : 0;
    }
  return 4 * inside >= nb * nc;
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
  // Each body's particles' extent (centre -+ half the spacing) and the spacing at the extremes.
  constexpr double inf = std::numeric_limits<double>::infinity();
  std::vector<std::array<double, 3>> lo(nb, {inf, inf, inf}), hi(nb, {-inf, -inf, -inf});
  std::vector<std::array<double, 3>> s_lo(nb, {0, 0, 0}), s_hi(nb, {0, 0, 0});
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
    for (int a = 0; a < dim; ++a) {
      if (xi[a] - 0.5 * s < lo[b][a]) {
        lo[b][a] = xi[a] - 0.5 * s;
        s_lo[b][a] = s;
      }
      if (xi[a] + 0.5 * s > hi[b][a]) {
        hi[b][a] = xi[a] + 0.5 * s;
        s_hi[b][a] = s;
      }
    }
  }
  const double tol = 1e-9 * lattice.h;
  for (std::size_t b = 0; b < nb; ++b) {
    const BodySpec& spec = scene.bodies[b];
    if (spec.shape == ShapeKind::Mesh || !std::isfinite(lo[b][0])) continue;
    const std::unique_ptr<Region> region = make_region(spec, scene);
    Vec3 box_lo, box_hi;
    region->bounds(box_lo, box_hi);
    for (int a = 0; a < dim; ++a)
      for (const bool upper : {false, true}) {
        const double face = upper ? box_hi[a] : box_lo[a];
        // A face the domain cuts off (a symmetry plane through the body, or a body reaching
        // out of the domain) is not the body's.
        if (face < lattice.origin[a] - tol || face > lattice.max()[a] + tol) continue;
        if (!flat_face(*region, box_lo, box_hi, a, upper, dim)) continue;
        const double filled = upper ? hi[b][a] : lo[b][a];
        const double s = upper ? s_hi[b][a] : s_lo[b][a];
        if (std::abs(filled - face) <= 0.01 * s) continue;
        out.push_back({b, a, upper, face, filled, s});
      }
  }
  return out;
}

std::string describe(const Scene& scene, const FaceOffset& f) {
  const char* axis = f.axis == 0 ? "x" : f.axis == 1 ? "y" : "z";
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
