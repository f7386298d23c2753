// Bodies to particles: primitive regions, the lattice, and the parallel voxeliser.
// Mesh regions (CGAL) live in mesh_region.cpp.
#include "mpm/prep/voxelise.hpp"

#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <bit>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <utility>
#include <vector>

#include "mpm/core/error.hpp"
#include "mpm/prep/mesh_region.hpp"
#include "mpm/scene/particles.hpp"

namespace mpm {

namespace {

std::string num(double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

/// Whole numbers as digits up to 1e18, then in exponent form.
std::string count_str(double n) {
  char buf[64];
  if (n < 1e18)
    std::snprintf(buf, sizeof buf, "%.0f", n);
  else
    std::snprintf(buf, sizeof buf, "%.3g", n);
  return buf;
}

const char* axis_name(int a) {
  return a == 0 ? "x" : a == 1 ? "y" : "z";
}

const char* shape_name(ShapeKind k) {
  switch (k) {
    case ShapeKind::Box:
      return "box";
    case ShapeKind::Cylinder:
      return "cylinder";
    case ShapeKind::Sphere:
      return "sphere";
    case ShapeKind::Mesh:
      return "mesh";
  }
  return "?";
}

bool finite(const Vec3& v) {
  return v.allFinite();
}

/// Box, cylinder and sphere (rectangle and disk in 2D). contains() maps the point back to the
/// local frame with the precomputed inverse placement, x_local = S^-1 R^T (x - t), and tests
/// the local shape exactly.
class PrimitiveRegion final : public Region {
 public:
  PrimitiveRegion(const BodySpec& body, int dim) : kind_(body.shape), dim_(dim) {
    Mat3 A = body_linear_map(body);
    Vec3 s = body.scale;
    t_ = body.translate;
    if (dim == 2) {
      // x-y plane only: no z scale, no z translation.
      A.row(2).setZero();
      A.col(2).setZero();
      A(2, 2) = 1;
      s.z() = 1;
      t_.z() = 0;
    }
    to_local_ = s.cwiseInverse().asDiagonal() * body_rotation(body).transpose();
    A_ = A;
    const double ascale = std::abs(s.x() * s.y() * s.z());
    r2_ = body.radius * body.radius;
    half_ = 0.5 * body.size;
    length_ = body.length;
    const double pi = std::numbers::pi;
    switch (kind_) {
      case ShapeKind::Box: {
        // Half extent along world axis a: sum_j |A_aj| half_j.
        Vec3 h = half_;
        if (dim == 2) h.z() = 0;
        const Vec3 e = A.cwiseAbs() * h;
        lo_ = t_ - e;
        hi_ = t_ + e;
        volume_ = (dim == 2 ? body.size.x() * body.size.y() : body.size.prod()) * ascale;
        break;
      }
      case ShapeKind::Sphere: {
        // Ellipsoid {A u + t : |u| <= r}: half extent along a is r |row a of A|.
        Vec3 e;
        for (int a = 0; a < 3; ++a) e[a] = body.radius * A.row(a).norm();
        if (dim == 2) e.z() = 0;
        lo_ = t_ - e;
        hi_ = t_ + e;
        volume_ = (dim == 2 ? pi * r2_ : 4.0 / 3.0 * pi * r2_ * body.radius) * ascale;
        break;
      }
      case ShapeKind::Cylinder: {
        // Union of the end disks' boxes: a disk {A (u, v, 0) + c : u^2 + v^2 <= r^2} has half
        // extent r sqrt(A_a0^2 + A_a1^2) along a.
        Vec3 e;
        for (int a = 0; a < 3; ++a) e[a] = body.radius * std::hypot(A(a, 0), A(a, 1));
        const Vec3 top = t_ + A * Vec3(0, 0, body.length);
        lo_ = t_.cwiseMin(top) - e;
        hi_ = t_.cwiseMax(top) + e;
        volume_ = pi * r2_ * body.length * ascale;
        break;
      }
      case ShapeKind::Mesh:
        break;  // not a primitive
    }
  }

  bool contains(const Vec3& x) const override {
    const Vec3 p = to_local_ * (x - t_);
    switch (kind_) {
      case ShapeKind::Box:
        return std::abs(p.x()) <= half_.x() && std::abs(p.y()) <= half_.y() &&
               (dim_ == 2 || std::abs(p.z()) <= half_.z());
      case ShapeKind::Sphere:
        return (dim_ == 2 ? p.x() * p.x() + p.y() * p.y() : p.squaredNorm()) <= r2_;
      case ShapeKind::Cylinder:
        return p.z() >= 0 && p.z() <= length_ && p.x() * p.x() + p.y() * p.y() <= r2_;
      case ShapeKind::Mesh:
        return false;
    }
    return false;
  }
  double volume() const override { return volume_; }
  void bounds(Vec3& lo, Vec3& hi) const override {
    lo = lo_;
    hi = hi_;
  }

  double revolved_volume() const override {
    if (dim_ != 2) return Region::revolved_volume();
    if (kind_ == ShapeKind::Sphere) {
      // The ellipse {A u + t : |u| <= R}: x = a.u + t_x with a the first row of A. With w the
      // coordinate of u along a, the integral of x over x >= 0 is |det A| times the integral
      // of (|a| w + t_x) 2 sqrt(R^2 - w^2) over w from max(-R, -t_x / |a|) to R.
      const double detA = std::abs(A_(0, 0) * A_(1, 1) - A_(0, 1) * A_(1, 0));
      const double R = std::sqrt(r2_), alpha = std::hypot(A_(0, 0), A_(0, 1));
      const double w0 = std::clamp(-t_.x() / alpha, -R, R);
      auto root = [&](double w) {
        return std::sqrt(std::max(0.0, (R - w) * (R + w)));
      };                        // 0 at w = +-R
      auto F = [&](double w) {  // of 2 sqrt(R^2 - w^2)
        return w * root(w) + R * R * std::asin(std::clamp(w / R, -1.0, 1.0));
      };
      auto G = [&](double w) {
        return -2.0 / 3.0 * std::pow(root(w), 3);
      };  // of 2 w sqrt(R^2 - w^2)
      return detA * (t_.x() * (F(R) - F(w0)) + alpha * (G(R) - G(w0)));
    }
    // The parallelogram of the box's corners, clipped to x >= 0 (one half-plane of
    // Sutherland-Hodgman); its integral of x by the polygon formula
    // (1/6) sum (x_i + x_j) (x_i y_j - x_j y_i), j = i + 1.
    std::vector<Vec<2>> in, out;
    for (const auto& [i, j] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
      const Vec3 c = A_ * Vec3(i * half_.x(), j * half_.y(), 0) + t_;
      in.emplace_back(c.x(), c.y());
    }
    for (std::size_t k = 0; k < in.size(); ++k) {
      const Vec<2>&p = in[k], &q = in[(k + 1) % in.size()];
      if (p.x() >= 0) out.push_back(p);
      if ((p.x() >= 0) != (q.x() >= 0))
        out.emplace_back(0.0, p.y() + (q.y() - p.y()) * (0 - p.x()) / (q.x() - p.x()));
    }
    double moment = 0;
    for (std::size_t k = 0; k < out.size(); ++k) {
      const Vec<2>&p = out[k], &q = out[(k + 1) % out.size()];
      moment += (p.x() + q.x()) * (p.x() * q.y() - q.x() * p.y());
    }
    return std::abs(moment) / 6.0;
  }

 private:
  ShapeKind kind_;
  int dim_;
  Mat3 A_;
  Mat3 to_local_;
  Vec3 t_, half_, lo_, hi_;
  double r2_ = 0, length_ = 0, volume_ = 0;
};

/// Checks a body's shape parameters and placement; throws InputError at the offending key.
void check_body_shape(const BodySpec& body, const Scene& scene) {
  const int dim = scene.dimension;
  if (dim == 2 && (body.shape == ShapeKind::Cylinder || body.shape == ShapeKind::Mesh))
    throw InputError(body_where(scene, body, "shape"),
                     "body '" + body.name + "' is a " + shape_name(body.shape) +
                         "; a 2D scene takes only box (a rectangle) and sphere (a disk)");
  for (int a = 0; a < dim; ++a)
    if (!(body.scale[a] != 0) || !std::isfinite(body.scale[a]))
      throw InputError(body_where(scene, body, "scale"),
                       std::string("the scale along ") + axis_name(a) +
                           " must be a non-zero number (got " + num(body.scale[a]) + ")");
  if (!finite(body.rotate_deg))
    throw InputError(body_where(scene, body, "rotate_deg"), "the rotation must be finite");
  if (!finite(body.translate))
    throw InputError(body_where(scene, body, "translate"), "the translation must be finite");
  if (dim == 2 && (body.rotate_deg.x() != 0 || body.rotate_deg.y() != 0))
    throw InputError(body_where(scene, body, "rotate_deg"),
                     "a 2D scene rotates bodies only about z; the x and y angles must be 0");
  switch (body.shape) {
    case ShapeKind::Box:
      for (int a = 0; a < dim; ++a)
        if (!(body.size[a] > 0) || !std::isfinite(body.size[a]))
          throw InputError(body_where(scene, body, "size"),
                           std::string("the box's edge along ") + axis_name(a) +
                               " must be a positive length in m (got " + num(body.size[a]) + ")");
      break;
    case ShapeKind::Cylinder:
      if (!(body.length > 0) || !std::isfinite(body.length))
        throw InputError(
            body_where(scene, body, "length"),
            "the cylinder's length must be positive, in m (got " + num(body.length) + ")");
      [[fallthrough]];
    case ShapeKind::Sphere:
      if (!(body.radius > 0) || !std::isfinite(body.radius))
        throw InputError(
            body_where(scene, body, "radius"),
            "the radius must be a positive length in m (got " + num(body.radius) + ")");
      break;
    case ShapeKind::Mesh:
      break;  // checked when the file is read
  }
}

/// World bounding box of a body (reads mesh files but does not build their trees).
void body_bounds(const BodySpec& body, const Scene& scene, Vec3& lo, Vec3& hi) {
  check_body_shape(body, scene);
  if (body.shape == ShapeKind::Mesh) {
    mesh_body_bounds(body, scene, lo, hi);
  } else {
    PrimitiveRegion(body, scene.dimension).bounds(lo, hi);
  }
}

}  // namespace

Mat3 body_rotation(const BodySpec& body) {
  const double k = std::numbers::pi / 180.0;
  using Eigen::AngleAxisd;
  const Mat3 rx = AngleAxisd(k * body.rotate_deg.x(), Vec3::UnitX()).toRotationMatrix();
  const Mat3 ry = AngleAxisd(k * body.rotate_deg.y(), Vec3::UnitY()).toRotationMatrix();
  const Mat3 rz = AngleAxisd(k * body.rotate_deg.z(), Vec3::UnitZ()).toRotationMatrix();
  return rz * ry * rx;
}

Mat3 body_linear_map(const BodySpec& body) {
  return body_rotation(body) * body.scale.asDiagonal();
}

std::string body_where(const Scene& scene, const BodySpec& body, const std::string& field) {
  return where(scene.source, body.loc.line,
               "bodies." + body.name + (field.empty() ? "" : "." + field));
}

std::string resolve_mesh_path(const BodySpec& body, const Scene& scene) {
  const std::filesystem::path p(body.mesh_path);
  if (p.is_absolute() || scene.directory.empty()) return p.string();
  return (std::filesystem::path(scene.directory) / p).string();
}

std::unique_ptr<Region> make_region(const BodySpec& body, const Scene& scene) {
  check_body_shape(body, scene);
  if (body.shape == ShapeKind::Mesh) return std::make_unique<MeshRegion>(body, scene);
  return std::make_unique<PrimitiveRegion>(body, scene.dimension);
}

Lattice make_lattice(const Scene& scene) {
  const GridSpec& g = scene.grid;
  const int dim = scene.dimension;
  if (dim != 2 && dim != 3)
    throw InputError(where(scene.source, 0, "dimension"),
                     "the dimension must be 2 or 3 (got " + std::to_string(dim) + ")");
  const double h = g.cell_size;
  if (!(h > 0) || !std::isfinite(h))
    throw InputError(where(scene.source, g.loc.line, "grid.cell_size"),
                     "the cell size must be a positive length in m (got " + num(h) + ")");
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();
  if (g.domain_given) {
    lo = g.domain_min;
    hi = g.domain_max;
    for (int a = 0; a < dim; ++a)
      if (!std::isfinite(lo[a]) || !std::isfinite(hi[a]) || !(hi[a] > lo[a]))
        throw InputError(where(scene.source, g.loc.line, "grid.domain"),
                         std::string("the domain is empty along ") + axis_name(a) + " (from " +
                             num(lo[a]) + " m to " + num(hi[a]) + " m)");
  } else {
    if (!(g.padding >= 0) || !std::isfinite(g.padding))
      throw InputError(where(scene.source, g.loc.line, "grid.padding"),
                       "the padding must be a length >= 0 in m (got " + num(g.padding) + ")");
    if (scene.bodies.empty())
      throw InputError(where(scene.source, g.loc.line, "grid.domain"),
                       "no domain is given and there is no body to fit one around");
    lo = Vec3::Constant(std::numeric_limits<double>::infinity());
    hi = -lo;
    for (const BodySpec& b : scene.bodies) {
      Vec3 blo, bhi;
      body_bounds(b, scene, blo, bhi);
      lo = lo.cwiseMin(blo);
      hi = hi.cwiseMax(bhi);
    }
    lo.array() -= g.padding;
    hi.array() += g.padding;
  }
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
                       "the domain would need " + count_str(n) + " cells along " + axis_name(a) +
                           "; enlarge grid.cell_size or shrink the domain");
    lat.cells[a] = static_cast<int>(n);
    total *= n;
  }
  if (dim == 2) lat.cells[2] = 1;
  if (total > std::ldexp(1.0, 40))
    throw InputError(where(scene.source, g.loc.line, "grid.cell_size"),
                     "the domain would need " + count_str(total) +
                         " cells; enlarge grid.cell_size or shrink the domain");
  return lat;
}

namespace {

/// One body's voxelisation between the two passes: which lattice points it keeps.
/// Candidate points are grouped in rows of cells along x (row r: cell y = c0[1] + r % ny,
/// z = c0[2] + r / ny); row r owns `words` 64-bit words of `bits`, one bit per candidate in
/// output order (cell x, then the points of the cell, pz slowest, then py, px).
struct BodyPlan {
  std::array<long long, 3> c0{}, c1{};  // cell range [c0, c1) per axis
  long long ny = 0, rows = 0, words = 0;
  // Candidate points per axis, in increasing order: the coordinates (m) and, for each cell
  // c0 + c of the range, the first of its points (first[c] .. first[c + 1]). With
  // particles_per_cell = n every cell holds n; with particle_spacing the count varies.
  std::array<std::vector<double>, 3> at;
  std::array<std::vector<long long>, 3> first;
  std::vector<std::uint64_t> bits;
  std::vector<std::uint64_t> row_start;  // prefix sums of kept points per row (rows + 1)
  std::size_t kept = 0, skipped = 0;
  double spacing = 0, particle_volume = 0, mass = 0;
  long long count(int a, long long c) const { return first[a][c + 1] - first[a][c]; }
};

/// Density of a body's particles; rigid bodies carry a nominal 1 kg/m^3 (their mass is their
/// volume and takes no part in the dynamics).
double density_of(const Scene& scene, const BodySpec& body) {
  return body.rigid ? 1.0 : scene.materials[body.material].density;
}

}  // namespace

ColumnStore voxelise(const Scene& scene, const Lattice& lat, std::vector<BodyReport>& report,
                     const VoxeliseCells& cells) {
  report.clear();
  const int dim = lat.dim;
  const double h = lat.h;
  const std::size_t nb = scene.bodies.size();
  if (dim != 2 && dim != 3) throw std::logic_error("voxelise: lattice dimension must be 2 or 3");
  if (nb == 0) throw InputError(where(scene.source, 0, "bodies"), "the scene has no bodies");
  if (nb > 255)
    throw InputError(where(scene.source, scene.bodies[255].loc.line, "bodies"),
                     "the scene has " + std::to_string(nb) +
                         " bodies; a model holds at most 255 (body ids are 8-bit)");

  // Regions first: every mesh is read and checked before any long work.
  std::vector<std::unique_ptr<Region>> regions;
  std::vector<Vec3> blo(nb), bhi(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    const BodySpec& body = scene.bodies[b];
    if (!body.rigid &&
        (body.material < 0 || body.material >= int(scene.materials.size()) || body.material > 254))
      throw InputError(body_where(scene, body, "material"),
                       "body '" + body.name + "' has no valid material (index " +
                           std::to_string(body.material) + " of " +
                           std::to_string(scene.materials.size()) + ")");
    const double rho = density_of(scene, body);
    if (!(rho > 0) || !std::isfinite(rho))
      throw InputError(where(scene.source, scene.materials[body.material].loc.line,
                             "materials." + scene.materials[body.material].name + ".density"),
                       "the density must be positive, in kg/m^3 (got " + num(rho) + ")");
    if (body.particle_spacing <= 0 && (body.particles_per_cell < 1 || body.particles_per_cell > 16))
      throw InputError(body_where(scene, body, "particles_per_cell"),
                       "particles per cell (per axis) must be 1 to 16 (got " +
                           std::to_string(body.particles_per_cell) + ")");
    if (!finite(body.velocity))
      throw InputError(body_where(scene, body, "velocity"), "the velocity must be finite");
    regions.push_back(make_region(body, scene));
    regions.back()->bounds(blo[b], bhi[b]);
    if (dim == 2) blo[b].z() = bhi[b].z() = 0;
  }

  // Pass 1, body by body: test every candidate point, keep a bit per kept point.
  std::vector<BodyPlan> plans(nb);
  std::size_t total = 0;
  for (std::size_t b = 0; b < nb; ++b) {
    const BodySpec& body = scene.bodies[b];
    const Region& region = *regions[b];
    const MeshRegion* mesh = dynamic_cast<const MeshRegion*>(&region);
    BodyPlan& P = plans[b];
    const bool by_spacing = body.particle_spacing > 0;
    const int n = body.particles_per_cell;
    const double s = body.spacing(h);
    P.spacing = s;
    P.particle_volume =
        dim == 3 ? s * s * s : s * s * 1.0;  // 2D: 1 m thick (or per radian, times r)
    P.mass = density_of(scene, body) * P.particle_volume;

    bool empty = false;
    for (int a = 0; a < 3; ++a) {
      if (a >= dim) {
        P.c0[a] = 0;
        P.c1[a] = 1;
        continue;
      }
      const double cells = lat.cells[a];
      const double f0 = std::floor((blo[b][a] - lat.origin[a]) / h);
      const double f1 = std::ceil((bhi[b][a] - lat.origin[a]) / h);
      P.c0[a] = static_cast<long long>(std::clamp(f0, 0.0, cells));
      P.c1[a] = static_cast<long long>(std::clamp(f1, 0.0, cells));
      if (P.c1[a] <= P.c0[a]) empty = true;
    }
    const auto no_particles = [&](std::size_t skipped) {
      if (skipped > 0)
        return InputError(body_where(scene, body, ""),
                          "body '" + body.name + "' has no particles: all its " +
                              std::to_string(skipped) +
                              " lattice points lie inside earlier bodies");
      return InputError(body_where(scene, body, ""),
                        "body '" + body.name +
                            "' has no particles: it lies outside the domain or is thinner than "
                            "a particle spacing (" +
                            num(s) + " m)");
    };

    // Candidate points per axis, tabulated once so both passes use bit-identical values.
    // particles_per_cell: cell corner + (i + 1/2) h / n, n in every cell. particle_spacing: a
    // lattice centred on the body's bounding box, round(L / s) points along an extent L (at
    // least one), so a box whose edges are multiples of s is tiled exactly and a sphere's
    // lattice is symmetric about its centre; each point belongs to the cell it lies in.
    std::array<long long, 3> most{1, 1, 1};  // most points of one cell along each axis
    for (int a = 0; a < 3 && !empty; ++a) {
      const long long m = a < dim ? P.c1[a] - P.c0[a] : 1;
      auto& at = P.at[a];
      auto& first = P.first[a];
      at.clear();
      first.assign(std::size_t(m) + 1, 0);
      if (a >= dim) {
        at.push_back(0.0);
        first[1] = 1;
        continue;
      }
      if (!by_spacing) {
        for (long long c = 0; c < m; ++c) {
          for (int i = 0; i < n; ++i)
            at.push_back(lat.origin[a] + h * double(P.c0[a] + c) + (i + 0.5) * s);
          first[std::size_t(c) + 1] = (c + 1) * n;
        }
        most[a] = n;
        continue;
      }
      const double extent = bhi[b][a] - blo[b][a];
      const double centre = 0.5 * (blo[b][a] + bhi[b][a]);
      const long long points = std::max(1LL, std::llround(extent / s));
      const double x0 = centre - 0.5 * double(points - 1) * s;
      for (long long i = 0; i < points; ++i) {
        const double x = x0 + double(i) * s;
        const double c = std::floor((x - lat.origin[a]) / h) - double(P.c0[a]);
        if (c < 0 || c >= double(m)) continue;  // outside the domain
        at.push_back(x);
        ++first[std::size_t(c) + 1];
      }
      for (long long c = 0; c < m; ++c) {
        most[a] = std::max(most[a], first[std::size_t(c) + 1]);
        first[std::size_t(c) + 1] += first[std::size_t(c)];
      }
      if (at.empty()) empty = true;
    }
    if (empty && cells.allow_empty) continue;  // nothing of this body in these cells
    if (empty) throw no_particles(0);

    const long long ncx = P.c1[0] - P.c0[0];
    P.ny = P.c1[1] - P.c0[1];
    P.rows = P.ny * (P.c1[2] - P.c0[2]);
    // Row r's points in output order: cell x, then the points of the cell (z slowest, then y,
    // x); the cell at ix starts at first_x[ix] * (points of the row's cell along y and z).
    const long long row_points = static_cast<long long>(P.at[0].size()) * most[1] * most[2];
    P.words = (row_points + 63) / 64;
    const double candidates = double(P.rows) * double(P.words) * 64.0;
    if (candidates > std::ldexp(1.0, 38))
      throw InputError(body_where(scene, body, ""),
                       "body '" + body.name + "' spans " + count_str(candidates) +
                           " lattice points; a model holds at most 4294967295 particles");
    P.bits.assign(std::size_t(P.rows * P.words), 0);

    // Earlier bodies whose boxes meet this one's: a point inside one of them is skipped.
    std::vector<std::size_t> earlier;
    for (std::size_t j = 0; j < b; ++j)
      if ((blo[j].array() <= bhi[b].array()).all() && (bhi[j].array() >= blo[b].array()).all())
        earlier.push_back(j);

    std::vector<std::uint64_t> row_kept(std::size_t(P.rows), 0),
        row_skipped(std::size_t(P.rows), 0);
    const double z_step = dim == 3 ? h : 0.0;
#pragma omp parallel for schedule(dynamic, 8)
    for (long long r = 0; r < P.rows; ++r) {
      const long long iy = r % P.ny, iz = r / P.ny;
      const long long y0i = P.first[1][std::size_t(iy)], cy = P.count(1, iy);
      const long long z0i = P.first[2][std::size_t(iz)], cz = P.count(2, iz);
      std::uint64_t* w = P.bits.data() + r * P.words;
      std::uint64_t kept = 0, skipped = 0;
      // known = 1: the cell is wholly inside the region (only earlier bodies are tested).
      const auto test_cell = [&](long long ix, int known) {
        if (cells.keep && !cells.keep({P.c0[0] + ix, P.c0[1] + iy, P.c0[2] + iz})) return;
        const long long x0i = P.first[0][std::size_t(ix)], cx = P.count(0, ix);
        std::uint64_t idx = std::uint64_t(x0i * cy * cz);
        for (long long pz = 0; pz < cz; ++pz) {
          const double z = P.at[2][std::size_t(z0i + pz)];
          for (long long py = 0; py < cy; ++py) {
            const double y = P.at[1][std::size_t(y0i + py)];
            for (long long px = 0; px < cx; ++px, ++idx) {
              const Vec3 x(P.at[0][std::size_t(x0i + px)], y, z);
              if (known != 1 && !region.contains(x)) continue;
              bool taken = false;
              for (std::size_t j : earlier)
                if ((x.array() >= blo[j].array()).all() && (x.array() <= bhi[j].array()).all() &&
                    regions[j]->contains(x)) {
                  taken = true;
                  break;
                }
              if (taken) {
                ++skipped;
                continue;
              }
              w[idx >> 6] |= std::uint64_t(1) << (idx & 63);
              ++kept;
            }
          }
        }
      };
      if (mesh) {
        // Bisect the row: boxes of cells the surface misses are wholly in or out, so only
        // the cells the surface cuts are tested point by point.
        const double y0 = lat.origin[1] + h * double(P.c0[1] + iy);
        const double z0 = lat.origin[2] + h * double(P.c0[2] + iz);
        const auto corner_x = [&](long long ix) {
          return lat.origin[0] + h * double(P.c0[0] + ix);
        };
        const auto segment = [&](auto&& self, long long a, long long e) -> void {
          const int side =
              mesh->classify_box(Vec3(corner_x(a), y0, z0), Vec3(corner_x(e), y0 + h, z0 + z_step));
          if (side == 0) return;
          if (side == 1) {
            for (long long ix = a; ix < e; ++ix) test_cell(ix, 1);
          } else if (e - a == 1) {
            test_cell(a, -1);
          } else {
            const long long m = a + (e - a) / 2;
            self(self, a, m);
            self(self, m, e);
          }
        };
        segment(segment, 0, ncx);
      } else {
        for (long long ix = 0; ix < ncx; ++ix) test_cell(ix, -1);
      }
      row_kept[std::size_t(r)] = kept;
      row_skipped[std::size_t(r)] = skipped;
    }
    P.row_start.assign(std::size_t(P.rows) + 1, 0);
    for (long long r = 0; r < P.rows; ++r) {
      P.row_start[std::size_t(r) + 1] = P.row_start[std::size_t(r)] + row_kept[std::size_t(r)];
      P.skipped += row_skipped[std::size_t(r)];
    }
    P.kept = P.row_start.back();
    if (P.kept == 0 && !cells.allow_empty) throw no_particles(P.skipped);
    total += P.kept;
    if (total > std::numeric_limits<std::uint32_t>::max())
      throw InputError(body_where(scene, body, ""),
                       "the bodies up to '" + body.name + "' make " + std::to_string(total) +
                           " particles; a model holds at most 4294967295 (ids are 32-bit)");
  }

  // Pass 2: fill the columns, every body's rows at their prefix-sum offsets.
  ColumnStore store;
  store.add({"id", ScalarType::U32, 1, "-"});
  store.add({"body", ScalarType::U8, 1, "-"});
  store.add({"material", ScalarType::U8, 1, "-"});
  store.add({"x", ScalarType::F64, dim, "m"});
  store.add({"v", ScalarType::F64, dim, "m/s"});
  store.add({"m", ScalarType::F64, 1, "kg"});
  store.add({"rho", ScalarType::F64, 1, "kg/m^3"});
  store.resize(total);
  auto* id = store.get<std::uint32_t>("id");
  auto* bcol = store.get<std::uint8_t>("body");
  auto* mcol = store.get<std::uint8_t>("material");
  double* xcol = reinterpret_cast<double*>(store.at("x").data());
  double* vcol = reinterpret_cast<double*>(store.at("v").data());
  auto* mass = store.get<double>("m");
  auto* rho = store.get<double>("rho");

  std::size_t base = 0;
  for (std::size_t b = 0; b < nb; ++b) {
    const BodySpec& body = scene.bodies[b];
    const BodyPlan& P = plans[b];
    const double density = density_of(scene, body);
    const auto body_id = static_cast<std::uint8_t>(b);
    const auto mat_id = static_cast<std::uint8_t>(body.rigid ? kRigidMaterial : body.material);
    const bool axi = scene.axisymmetric;
#pragma omp parallel for schedule(dynamic, 8)
    for (long long r = 0; r < P.rows; ++r) {
      const long long iy = r % P.ny, iz = r / P.ny;
      const long long y0i = P.first[1][std::size_t(iy)], cy = P.count(1, iy);
      const long long z0i = P.first[2][std::size_t(iz)], cz = P.count(2, iz);
      const std::uint64_t per_x = std::uint64_t(cy * cz);  // points per x point of this row
      std::size_t k = base + P.row_start[std::size_t(r)];
      const std::uint64_t* w = P.bits.data() + r * P.words;
      const auto& first_x = P.first[0];
      std::size_t ix = 0;  // the cell of the current point: the bits come in increasing order
      for (long long wi = 0; wi < P.words; ++wi) {
        std::uint64_t word = w[wi];
        while (word) {
          const std::uint64_t idx = std::uint64_t(wi) * 64 + std::uint64_t(std::countr_zero(word));
          word &= word - 1;
          while (std::uint64_t(first_x[ix + 1]) * per_x <= idx) ++ix;
          const long long cx = first_x[ix + 1] - first_x[ix];
          const long long p = static_cast<long long>(idx - std::uint64_t(first_x[ix]) * per_x);
          const long long px = p % cx, py = (p / cx) % cy, pz = p / (cx * cy);
          double* x = xcol + k * dim;
          double* v = vcol + k * dim;
          x[0] = P.at[0][std::size_t(first_x[ix] + px)];
          x[1] = P.at[1][std::size_t(y0i + py)];
          v[0] = body.velocity.x();
          v[1] = body.velocity.y();
          if (dim == 3) {
            x[2] = P.at[2][std::size_t(z0i + pz)];
            v[2] = body.velocity.z();
          }
          id[k] = static_cast<std::uint32_t>(k);
          bcol[k] = body_id;
          mcol[k] = mat_id;
          mass[k] = axi ? P.mass * x[0] : P.mass;  // axisymmetric: per radian, A r
          rho[k] = density;
          ++k;
        }
      }
    }
    base += P.kept;

    BodyReport rep;
    rep.name = body.name;
    rep.particles = P.kept;
    rep.mass = 0;
    for (std::size_t k = base - P.kept; k < base; ++k) rep.mass += mass[k];
    // 2D: area x 1 m; axisymmetric: per radian, the part at r >= 0 (a body may cross the axis:
    // a disk centred on it is a sphere).
    rep.exact_mass = density * (axi ? regions[b]->revolved_volume() : regions[b]->volume());
    rep.spacing = P.spacing;
    rep.skipped_overlap = P.skipped;
    report.push_back(rep);
  }
  return store;
}

double Region::revolved_volume() const {
  throw std::logic_error(
      "revolved_volume: only the 2D primitives (boxes and disks) sweep a solid of revolution");
}

}  // namespace mpm
