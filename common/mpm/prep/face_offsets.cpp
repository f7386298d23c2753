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
  const double tol = 1e-9 * lattice.h;
  for (std::size_t b = 0; b < nb; ++b) {
    const BodySpec& spec = scene.bodies[b];
    if (spec.shape == ShapeKind::Mesh || ext[b].empty()) continue;
    std::sort(ext[b].begin(), ext[b].end(),
              [](const Extent& p, const Extent& q) { return p.s > q.s; });  // coarsest first
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
        for (const Extent& e : ext[b]) {
          const double filled = upper ? e.hi[a] : e.lo[a];
          const double off = std::abs(filled - face);
          // Particles of this spacing that do not reach the face (a level away from it) fill
          // it nowhere; those that do are within half their spacing of it.
          if (off <= 0.01 * e.s || off > 0.5 * e.s * (1 + 1e-6)) continue;
          out.push_back({b, a, upper, face, filled, e.s});
        }
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
