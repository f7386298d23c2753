// What a scene models that it might not need (issue 22, "model only what the scene
// requires"): each finding comes with the figure measured from the scene and its particles.
#include "mpm/prep/scene_needs.hpp"

#include <cmath>
#include <cstdio>

#include "mpm/scene/particles.hpp"
#include "mpm/solver/materials/material.hpp"

namespace mpm {

namespace {

std::string format(const char* fmt, double a, double b = 0, double c = 0, double d = 0,
                   double e = 0) {
  char buf[400];
  std::snprintf(buf, sizeof buf, fmt, a, b, c, d, e);
  return buf;
}

/// A 3D scene whose bodies are unrotated cylinders along z and spheres on one line parallel
/// to z, moving along it, with no fields, loads, levels or sideways gravity, and whose x and y
/// faces are free or mirror planes through that line, is a solid of revolution: the particles
/// of its axisymmetric model (a ring per particle of the half section r >= 0) at the same
/// spacing, against the 3D model's.
void axisymmetry(const Scene& scene, const std::vector<BodyReport>& report,
                 std::vector<std::string>& out) {
  if (scene.dimension != 3 || !scene.loads.empty() || !scene.grid.levels.empty() ||
      scene.solver.gravity.x() != 0 || scene.solver.gravity.y() != 0 || scene.bodies.empty())
    return;
  double ax = 0, ay = 0, axi = 0, full = 0;
  for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
    const BodySpec& body = scene.bodies[b];
    const bool round = body.shape == ShapeKind::Sphere ||
                       (body.shape == ShapeKind::Cylinder && body.rotate_deg.isZero(0));
    if (!round || body.has_initial_fields() || body.velocity.x() != 0 || body.velocity.y() != 0 ||
        body.scale != Vec3::Ones())
      return;
    const double tol = 1e-9 * std::max(body.radius, 1e-3);
    if (b == 0) ax = body.translate.x(), ay = body.translate.y();
    if (std::abs(body.translate.x() - ax) > tol || std::abs(body.translate.y() - ay) > tol) return;
    const double s = report[b].spacing;
    axi += (body.shape == ShapeKind::Sphere ? 0.5 * M_PI * body.radius * body.radius
                                            : body.radius * body.length) /
           (s * s);
    full += double(report[b].particles);
  }
  for (int a = 0; a < 2; ++a) {
    const double at = a == 0 ? ax : ay;
    for (int side = 0; side < 2; ++side) {
      const BoundaryType f = scene.boundary.face[2 * a + side];
      const double face = side == 0 ? scene.grid.domain_min[a] : scene.grid.domain_max[a];
      const bool mirror = f == BoundaryType::Slip && std::abs(face - at) < 1e-9;
      if (f != BoundaryType::Free && !mirror) return;
    }
  }
  if (full <= 0) return;
  out.push_back(format(
      "axisymmetric would do: the bodies, their velocities and the x and y faces are symmetric "
      "about the line x = %.4g mm, y = %.4g mm; dimension = 2, geometry = \"axisymmetric\" "
      "would hold about %.3g particles at the same spacing instead of %.3g (1/%.0f)",
      ax * 1e3, ay * 1e3, axi, full, full / axi));
}

/// For each material with a nonlinear EOS: the Hugoniot state at the fastest particle's speed
/// (the shock onto a rigid wall: an upper bound of the scene's impacts) against the linear
/// p = K mu at the same compression.
void equation_of_state(const Scene& scene, const ColumnStore& cols, std::vector<std::string>& out) {
  const auto* mat = cols.get<std::uint8_t>(col::material);
  const auto* v = reinterpret_cast<const double*>(cols.at(col::v).data());
  const int d = scene.dimension;
  std::vector<double> v_max(scene.materials.size(), 0.0);
  for (std::size_t i = 0; i < cols.size(); ++i) {
    if (mat[i] >= scene.materials.size()) continue;  // rigid particles, rebar nodes
    double s2 = 0;
    for (int a = 0; a < d; ++a) s2 += v[i * d + a] * v[i * d + a];
    v_max[mat[i]] = std::max(v_max[mat[i]], std::sqrt(s2));
  }
  for (std::size_t k = 0; k < scene.materials.size(); ++k) {
    const MaterialSpec& spec = scene.materials[k];
    if (spec.eos.model == EosModel::Linear || !(v_max[k] > 0)) continue;
    const Material m(spec, scene.solver);
    const double u_p = v_max[k], rho0 = spec.density;
    const double rho = m.hugoniot_density(u_p);
    if (!(rho > rho0)) continue;
    const double p = rho0 * u_p * u_p * rho / (rho - rho0), mu = rho / rho0 - 1;
    const double K = spec.bulk_modulus(), gap = std::abs(p - K * mu) / p;
    const std::string head = gap < 0.05 ? "linear EOS would do for '" + spec.name + "': "
                                        : "the EOS of '" + spec.name + "' matters: ";
    out.push_back(head + format("the peak pressure estimate %.3g MPa (the Hugoniot at the "
                                "fastest particle's %.4g m/s, as onto a rigid wall) is %.2g%% of "
                                "its bulk modulus, and K mu at that compression differs from it "
                                "by %.1f%%",
                                p / 1e6, u_p, 100 * p / K, 100 * gap));
  }
}

/// The share of the grid window's cells that hold particles at the start, and the memory of
/// the dense window against the sparse grid's (the occupied cells widened by one cell, a node
/// each, and a 4-byte entry per cell of the box).
void sparse(const Scene& scene, const Lattice& lattice, const ColumnStore& cols,
            std::vector<std::string>& out) {
  if (scene.grid.sparse || !scene.grid.levels.empty() || cols.size() == 0 ||
      scene.solver.type != SolverType::Explicit)
    return;
  const int d = scene.dimension;
  const auto* x = reinterpret_cast<const double*>(cols.at(col::x).data());
  std::array<long long, 3> lo{1LL << 60, 1LL << 60, 0}, hi{-(1LL << 60), -(1LL << 60), 0};
  auto cell = [&](std::size_t i, int a) {
    return (long long)std::floor((x[i * d + a] - lattice.origin[a]) / lattice.h);
  };
  for (std::size_t i = 0; i < cols.size(); ++i)
    for (int a = 0; a < d; ++a)
      lo[a] = std::min(lo[a], cell(i, a)), hi[a] = std::max(hi[a], cell(i, a));
  std::array<long long, 3> n{1, 1, 1};
  double box = 1;
  for (int a = 0; a < d; ++a) lo[a] -= 1, hi[a] += 1, n[a] = hi[a] - lo[a] + 1, box *= double(n[a]);
  if (box > 2e8) return;  // a bitmap of the window would be too large to be worth it here
  std::vector<std::uint8_t> occupied(std::size_t(box), 0);
  auto index = [&](const std::array<long long, 3>& c) {
    return std::size_t((c[2] - lo[2]) * n[1] * n[0] + (c[1] - lo[1]) * n[0] + (c[0] - lo[0]));
  };
  std::size_t held = 0;
  for (std::size_t i = 0; i < cols.size(); ++i) {
    std::array<long long, 3> c{cell(i, 0), cell(i, 1), d == 3 ? cell(i, 2) : 0};
    std::uint8_t& o = occupied[index(c)];
    held += o == 0;
    o = 1;
  }
  const double share = double(held) / box;
  if (share >= 0.5) return;
  // Widen by one cell: a cell counts when any of its neighbours holds particles.
  std::size_t widened = 0;
  for (long long k = lo[2]; k <= hi[2]; ++k)
    for (long long j = lo[1]; j <= hi[1]; ++j)
      for (long long i = lo[0]; i <= hi[0]; ++i) {
        bool any = false;
        for (long long dk = (d == 3 ? -1 : 0); dk <= (d == 3 ? 1 : 0) && !any; ++dk)
          for (long long dj = -1; dj <= 1 && !any; ++dj)
            for (long long di = -1; di <= 1 && !any; ++di) {
              const std::array<long long, 3> c{i + di, j + dj, k + dk};
              bool inside = true;
              for (int a = 0; a < d; ++a) inside = inside && c[a] >= lo[a] && c[a] <= hi[a];
              any = inside && occupied[index(c)];
            }
        widened += any;
      }
  const double node = grid_node_bytes(d);
  out.push_back(format(
      "sparse grid would do: %.3g%% of the grid window's %.0f cells hold particles at the start; "
      "grid.sparse = true would hold about %.3g MB of nodes instead of %.3g MB (as the material "
      "spreads, the window grows and the sparse grid follows only the occupied cells)",
      100 * share, box, (double(widened) * node + box * 4) / 1e6, box * node / 1e6));
}

}  // namespace

std::vector<std::string> scene_needs(const Scene& scene, const Lattice& lattice,
                                     const ColumnStore& cols,
                                     const std::vector<BodyReport>& report) {
  std::vector<std::string> out;
  axisymmetry(scene, report, out);
  equation_of_state(scene, cols, out);
  sparse(scene, lattice, cols, out);
  return out;
}

}  // namespace mpm
