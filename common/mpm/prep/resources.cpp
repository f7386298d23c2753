// What a model will need, estimated before any particle is made (resources.hpp).
#include "mpm/prep/resources.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "mpm/core/cli.hpp"
#include "mpm/core/error.hpp"
#include "mpm/core/units.hpp"
#include "mpm/prep/region.hpp"
#include "mpm/scene/particles.hpp"

namespace mpm {

namespace {

/// Bytes of a particle of the model mpm-prep writes: id, body, material, x, v, m, rho.
double model_particle_bytes(int dim) {
  return 4 + 1 + 1 + 2 * dim * 8 + 8 + 8;
}

}  // namespace

ResourceEstimate estimate_resources(const Scene& scene, const BodyBoxes& boxes) {
  const int d = scene.dimension;
  const GridSpec& g = scene.grid;
  const double h = g.cell_size;
  // The domain: given, or the bodies' boxes with the padding.
  Vec3 d_lo = g.domain_min, d_hi = g.domain_max;
  if (!g.domain_given) {
    d_lo = Vec3::Constant(1e300), d_hi = Vec3::Constant(-1e300);
    for (std::size_t b = 0; b < boxes.lo.size(); ++b)
      d_lo = d_lo.cwiseMin(boxes.lo[b]), d_hi = d_hi.cwiseMax(boxes.hi[b]);
    d_lo.array() -= g.padding;
    d_hi.array() += g.padding;
  }
  ResourceEstimate e;
  Vec3 w_lo = Vec3::Constant(1e300), w_hi = Vec3::Constant(-1e300);  // the grid window
  double bits = 0;
  for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
    const BodySpec& body = scene.bodies[b];
    const double s = body.spacing(h);
    double clipped = 1, box = 1, rows = 1;
    for (int a = 0; a < d; ++a) {
      const double lo = std::max(boxes.lo[b][a], d_lo[a]), hi = std::min(boxes.hi[b][a], d_hi[a]);
      clipped *= std::max(0.0, hi - lo);
      box *= std::max(boxes.hi[b][a] - boxes.lo[b][a], 1e-300);
      if (a > 0) rows *= std::max(1.0, std::ceil((hi - lo) / h));
      w_lo[a] = std::min(w_lo[a], lo), w_hi[a] = std::max(w_hi[a], hi);
    }
    // The share of its box the body fills: exact for the primitives; a mesh is counted as its
    // box (reading its volume would need the whole mesh checked).
    const double fill = body.shape == ShapeKind::Mesh
                            ? 1.0
                            : std::min(1.0, make_region(body, scene)->volume() / box);
    const double points = clipped / std::pow(s, d);
    e.body_particles.push_back(fill * points);
    e.particles += fill * points;
    bits += points + 64 * rows;  // a bit per candidate point, rows padded to 64-bit words
  }
  double nodes = 1;
  for (int a = 0; a < d; ++a) nodes *= std::max(0.0, std::floor((w_hi[a] - w_lo[a]) / h)) + 4;
  e.prep_bytes = bits / 8 + e.particles * model_particle_bytes(d);
  e.particle_bytes = e.particles * run_particle_bytes(scene);
  e.grid_bytes = nodes * grid_node_bytes(d);
  return e;
}

void check_resources(const Scene& scene, const ResourceEstimate& e, double limit) {
  const double need = std::max(e.prep_bytes, e.run_bytes());
  if (!(need > limit)) return;
  std::string bodies;
  for (std::size_t b = 0; b < e.body_particles.size(); ++b)
    bodies += (b ? ", " : "") + scene.bodies[b].name + " " +
              format_count(std::round(e.body_particles[b]));
  char text[400];
  std::snprintf(text, sizeof text,
                "the model would need about %s particles (%s) and %s of memory (mpm-prep %s; "
                "mpm-run %s for the particles and %s for the grid), more than the limit of %s "
                "(--max-memory; by default the machine's memory)",
                format_count(std::round(e.particles)).c_str(), bodies.c_str(),
                format_bytes(need).c_str(), format_bytes(e.prep_bytes).c_str(),
                format_bytes(e.particle_bytes).c_str(), format_bytes(e.grid_bytes).c_str(),
                format_bytes(limit).c_str());
  throw InputError(where(scene.source, scene.grid.loc.line, "grid.cell_size"),
                   std::string(text) + "; enlarge grid.cell_size (now " +
                       format_mm(scene.grid.cell_size) +
                       " mm), lower particles_per_cell, or shrink the bodies or the domain");
}

}  // namespace mpm
