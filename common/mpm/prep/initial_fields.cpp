#include "mpm/prep/initial_fields.hpp"

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

#include "mpm/core/error.hpp"
#include "mpm/core/expression.hpp"
#include "mpm/prep/body_placement.hpp"
#include "mpm/prep/mesh_region.hpp"
#include "mpm/prep/region.hpp"
#include "mpm/scene/particles.hpp"
#include "mpm/solver/materials/material.hpp"

namespace mpm {

namespace {

/// The body's bounding box as placed (m; z = 0 in 2D).
void body_box(const Scene& scene, const BodySpec& body, Vec3& lo, Vec3& hi) {
  if (body.shape == ShapeKind::Mesh)
    mesh_body_bounds(body, scene, lo, hi);
  else
    make_region(body, scene)->bounds(lo, hi);
  if (scene.dimension == 2) lo.z() = hi.z() = 0;
}

/// The density (kg/m^3) at which the material's EOS gives pressure p (Pa) at zero internal
/// energy, by bisection on (rho0 / 2, 20 rho0) (A(rho) rises with rho); nullopt when p is
/// outside that range's pressures.
std::optional<double> density_at_pressure(const Material& mat, double p) {
  const double rho0 = mat.spec().density;
  const auto A_of = [&](double rho) {
    double A, B, K, e = 0;
    mat.eos().coefficients(1, &rho, &e, &A, &B, &K);
    return A;
  };
  if (p == 0) return rho0;
  double lo = 0.5 * rho0, hi = 20 * rho0;
  if (A_of(lo) > p || A_of(hi) < p) return std::nullopt;
  for (int it = 0; it < 200 && hi - lo > 1e-15 * rho0; ++it) {
    const double mid = 0.5 * (lo + hi);
    (A_of(mid) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

std::string at_position(const double* x) {
  char b[96];
  std::snprintf(b, sizeof b, "(%.6g, %.6g, %.6g) m", x[0], x[1], x[2]);
  return b;
}

/// The particles `idx` of body b: its spin, velocity field and stress field.
class BodyFieldPass {
 public:
  BodyFieldPass(const Scene& scene, const BodySpec& body, ColumnStore& cols)
      : scene_(scene), body_(body), d_(scene.dimension) {
    body_box(scene, body, lo_, hi_);
    centre_ = 0.5 * (lo_ + hi_);
    spin_centre_ = body.spin_centre_given ? body.spin_centre : centre_;
    if (d_ == 2) spin_centre_.z() = 0;
    x_ = reinterpret_cast<const double*>(cols.at(col::x).data());
    v_ = reinterpret_cast<double*>(cols.at(col::v).data());
    m_ = cols.get<double>(col::m);
    rho_ = cols.get<double>(col::rho);
    sigma_ = cols.get<Sym>(col::sigma);
    if (!body.stress_field.empty()) material_.emplace(scene.materials[body.material], scene.solver);
  }

  /// Sets the particles idx[k], k in [0, n); throws InputError at the first bad value.
  void run(const std::size_t* idx, long long n) {
    std::string error;  // the first bad value's message (no exception leaves a parallel loop)
#pragma omp parallel
    {
      Thread t(*this);  // the formulas compiled in the scene parser: this cannot throw
#pragma omp for schedule(static)
      for (long long k = 0; k < n; ++k) {
        try {
          particle(t, idx[k]);
        } catch (const InputError& e) {
#pragma omp critical(mpm_initial_fields)
          if (error.empty()) error = e.what();
        }
      }
    }
    if (!error.empty()) throw InputError("", error);
  }

 private:
  /// One thread's compiled formulas over its own variables.
  struct Thread {
    std::array<double, 10> var{};  // field_variables(): x y z r, then the body's box
    std::vector<std::unique_ptr<Expression>> v, sigma;
    explicit Thread(const BodyFieldPass& p) {
      for (int a = 0; a < 3; ++a) var[4 + 2 * a] = p.lo_[a], var[5 + 2 * a] = p.hi_[a];
      for (const auto& f : p.body_.velocity_field)
        v.push_back(std::make_unique<Expression>(f.text, field_variables(), var.data()));
      for (const auto& f : p.body_.stress_field)
        sigma.push_back(std::make_unique<Expression>(f.text, field_variables(), var.data()));
    }
  };

  /// The value of formula f of `field` at x; InputError when it is not finite.
  double value(const Expression& e, const FieldExpression& f, const double* x) const {
    const double y = e.eval();
    if (!std::isfinite(y))
      throw InputError(where(f.loc.file, f.loc.line, f.loc.key),
                       "the formula '" + f.text + "' gives " +
                           (std::isnan(y) ? "NaN" : "an infinite value") + " at " + at_position(x) +
                           " (a particle of body '" + body_.name + "')");
    return y;
  }

  void particle(Thread& t, std::size_t i) const {
    const double* xi = x_ + i * d_;
    const Vec3 x(xi[0], xi[1], d_ == 3 ? xi[2] : 0.0);
    for (int a = 0; a < 3; ++a) t.var[a] = x[a];
    t.var[3] = (x - centre_).norm();
    const Vec3 spin = body_.angular_velocity.cross(x - spin_centre_);
    double* v = v_ + i * d_;
    for (int a = 0; a < d_; ++a)
      v[a] += spin[a] + (t.v.empty() ? 0.0 : value(*t.v[a], body_.velocity_field[a], x.data()));
    if (t.sigma.empty()) return;
    Sym s;
    for (int c = 0; c < 6; ++c) s[c] = value(*t.sigma[c], body_.stress_field[c], x.data());
    const double p = -trace(s) / 3.0;
    const auto rho = density_at_pressure(*material_, p);
    if (!rho)
      throw InputError(body_where(scene_, body_, "stress_field"),
                       "the stress field's pressure " + std::to_string(p) + " Pa at " +
                           at_position(x.data()) +
                           " needs a density outside rho0 / 2 to 20 rho0 of the material's EOS");
    sigma_[i] = s;
    m_[i] *= *rho / rho_[i];
    rho_[i] = *rho;
  }

  const Scene& scene_;
  const BodySpec& body_;
  const int d_;
  Vec3 lo_, hi_, centre_, spin_centre_;
  const double* x_;
  double *v_, *m_, *rho_;
  Sym* sigma_;
  std::optional<Material> material_;
};

}  // namespace

void apply_initial_fields(const Scene& scene, ColumnStore& cols) {
  bool any = false, stress = false;
  for (const auto& b : scene.bodies) {
    any = any || b.has_initial_fields();
    stress = stress || !b.stress_field.empty();
  }
  if (!any) return;
  if (stress && !cols.has(col::sigma)) cols.add({col::sigma, ScalarType::F64, 6, "Pa"});
  // The particles of each body with fields, in one pass over the particles.
  std::vector<std::vector<std::size_t>> of_body(scene.bodies.size());
  const BodyIds body(cols.find(col::body));
  for (std::size_t i = 0; i < cols.size(); ++i) {
    const std::size_t b = std::size_t(body[i]);
    if (scene.bodies[b].has_initial_fields()) of_body[b].push_back(i);
  }
  for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
    if (of_body[b].empty()) continue;
    BodyFieldPass pass(scene, scene.bodies[b], cols);
    pass.run(of_body[b].data(), static_cast<long long>(of_body[b].size()));
  }
}

}  // namespace mpm
