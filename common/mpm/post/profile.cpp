// Profiles of particle fields along a line (mpm-post profile).
#include "mpm/post/profile.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <numeric>

#include "mpm/core/error.hpp"
#include "mpm/post/column_value.hpp"

namespace mpm {

namespace {

std::string available(const Frame& f) {
  std::string s;
  for (const Column& c : f.columns.columns())
    if (c.info().name != "x") s += (s.empty() ? "" : ", ") + c.info().name;
  return s + ", pressure, von_mises, speed";
}

/// The particles of a frame as profiles see them: positions, the body filter, weights.
struct ProfiledParticles {
  const Column* xc;
  const Column* body;
  const Column* mc;
  const Column* rc;
  int dim;
  int wanted_body;
  bool by_mass;  ///< weights m, else m / rho

  Vec3 pos(std::size_t i) const {
    Vec3 x = Vec3::Zero();
    for (int a = 0; a < dim; ++a) x[a] = column_value(*xc, i, a);
    return x;
  }
  bool selected(std::size_t i) const {
    return wanted_body < 0 || column_value(*body, i, 0) == wanted_body;
  }
  double weight(std::size_t i) const {
    if (by_mass) return column_value(*mc, i, 0);
    return mc && rc ? column_value(*mc, i, 0) / column_value(*rc, i, 0) : 1.0;
  }
};

/// The line of a profile, and which points lie near it.
struct ProfileLine {
  Vec3 from;
  Vec3 e;  ///< unit direction
  double length;
  double radius;

  /// Whether x lies within the radius of the segment; s: its position along the line.
  bool near(const Vec3& x, double& s) const {
    const Vec3 r = x - from;
    s = r.dot(e);
    return s >= -1e-12 * length && s <= length * (1 + 1e-12) &&
           (r - s * e).norm() <= radius * (1 + 1e-12);
  }
};

/// A row of a profile: position along the line, value, weight.
struct Row {
  double s, v, w;
};

/// The field to profile: a column (component or magnitude) or a derived one; sets p.unit.
std::function<double(std::size_t)> field_values(const Frame& frame, const ProfileOptions& o,
                                                Profile& p) {
  const ColumnStore& cols = frame.columns;
  const Column* sig = cols.find("sigma");
  if (const Column* c = cols.find(o.field)) {
    const int nc = c->info().components;
    if (o.component >= nc)
      throw InputError("--component", "field '" + o.field + "' has " + std::to_string(nc) +
                                          " components, got component " +
                                          std::to_string(o.component));
    p.unit = c->info().unit;
    if (o.component >= 0 || nc == 1) {
      const int k = std::max(o.component, 0);
      return [c, k](std::size_t i) { return column_value(*c, i, k); };
    }
    return [c, nc](std::size_t i) {
      double s = 0;
      for (int k = 0; k < nc; ++k) s += column_value(*c, i, k) * column_value(*c, i, k);
      return std::sqrt(s);
    };
  }
  if ((o.field == "pressure" || o.field == "von_mises") && sig) {
    p.unit = sig->info().unit;
    const bool pressure = o.field == "pressure";
    return [sig, pressure](std::size_t i) {
      Sym s;
      for (int k = 0; k < 6; ++k) s[k] = column_value(*sig, i, k);
      return pressure ? -trace(s) / 3.0 : von_mises(s);
    };
  }
  if (o.field == "speed" && cols.find("v")) {
    const Column* v = cols.find("v");
    p.unit = v->info().unit;
    return [v](std::size_t i) {
      double s = 0;
      for (int k = 0; k < v->info().components; ++k)
        s += column_value(*v, i, k) * column_value(*v, i, k);
      return std::sqrt(s);
    };
  }
  throw InputError("--field",
                   "unknown field '" + o.field + "' (available: " + available(frame) + ")");
}

/// The default line: along the axis over the selected particles' extent through their
/// centroid. Sets p.from and p.to.
void default_line(const Frame& frame, const ProfiledParticles& pp, int axis, Profile& p) {
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300), c = Vec3::Zero();
  std::size_t k = 0;
  for (std::size_t i = 0; i < frame.columns.size(); ++i) {
    if (!pp.selected(i)) continue;
    const Vec3 x = pp.pos(i);
    lo = lo.cwiseMin(x), hi = hi.cwiseMax(x), c += x, ++k;
  }
  if (k == 0)
    throw InputError("profile", "no particle to profile in the frame at t = " +
                                    std::to_string(frame.time) + " s");
  c /= double(k);
  p.from = c, p.to = c;
  p.from[axis] = lo[axis];
  p.to[axis] = hi[axis];
}

/// Rows of the grid nodes near the line: the field projected with the solver's linear shape
/// functions, mass-weighted.
std::vector<Row> grid_rows(const Frame& frame, const ProfiledParticles& pp,
                           const std::function<double(std::size_t)>& value, const ProfileLine& line,
                           const ProfileOptions& o) {
  if (!(o.cell > 0)) throw InputError("--grid", "the grid's cell size is unknown");
  const int dim = pp.dim;
  std::map<std::array<long, 3>, std::pair<double, double>> nodes;  // (sum w m v, sum w m)
  for (std::size_t i = 0; i < frame.columns.size(); ++i) {
    if (!pp.selected(i)) continue;
    const Vec3 xi = (pp.pos(i) - o.origin) / o.cell;
    std::array<long, 3> c{0, 0, 0};
    Vec3 f = Vec3::Zero();
    for (int a = 0; a < dim; ++a) c[a] = long(std::floor(xi[a])), f[a] = xi[a] - double(c[a]);
    const double m = pp.mc ? column_value(*pp.mc, i, 0) : 1.0, v = value(i);
    for (int corner = 0; corner < (1 << dim); ++corner) {
      std::array<long, 3> k = c;
      double w = m;
      for (int a = 0; a < dim; ++a) {
        const int up = (corner >> a) & 1;
        k[a] += up;
        w *= up ? f[a] : 1.0 - f[a];
      }
      auto& acc = nodes[k];
      acc.first += w * v;
      acc.second += w;
    }
  }
  std::vector<Row> rows;
  for (const auto& [k, acc] : nodes) {
    if (!(acc.second > 0)) continue;
    Vec3 x = o.origin;
    for (int a = 0; a < dim; ++a) x[a] += double(k[a]) * o.cell;
    double s;
    if (line.near(x, s)) rows.push_back({s, acc.first / acc.second, acc.second});
  }
  if (rows.empty())
    throw InputError("profile", "no grid node with mass lies within --radius of the line at t = " +
                                    std::to_string(frame.time) + " s (nodes are " +
                                    std::to_string(o.cell) + " m apart)");
  return rows;
}

/// Rows of the selected particles near the line.
std::vector<Row> particle_rows(const Frame& frame, const ProfiledParticles& pp,
                               const std::function<double(std::size_t)>& value,
                               const ProfileLine& line) {
  std::vector<Row> rows;
  for (std::size_t i = 0; i < frame.columns.size(); ++i) {
    double s;
    if (pp.selected(i) && line.near(pp.pos(i), s)) rows.push_back({s, value(i), pp.weight(i)});
  }
  if (rows.empty())
    throw InputError("profile", "no particle lies within --radius of the line at t = " +
                                    std::to_string(frame.time) + " s");
  return rows;
}

/// The rows (sorted by s) averaged in `bins` equal bins over the line into p.
void bin_rows(const std::vector<Row>& rows, double length, int bins, Profile& p) {
  const double width = length / bins;
  p.s.resize(bins);
  p.value.assign(bins, 0.0);
  p.weight.assign(bins, 0.0);
  p.min.assign(bins, std::numeric_limits<double>::quiet_NaN());
  p.max.assign(bins, std::numeric_limits<double>::quiet_NaN());
  p.count.assign(bins, 0);
  for (int b = 0; b < bins; ++b) p.s[b] = (b + 0.5) * width;
  for (const Row& r : rows) {
    const int b = std::clamp(int(r.s / width), 0, bins - 1);
    p.value[b] += r.w * r.v;
    p.weight[b] += r.w;
    p.min[b] = p.count[b] ? std::min(p.min[b], r.v) : r.v;
    p.max[b] = p.count[b] ? std::max(p.max[b], r.v) : r.v;
    ++p.count[b];
  }
  for (int b = 0; b < bins; ++b)
    p.value[b] =
        p.weight[b] > 0 ? p.value[b] / p.weight[b] : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

int component_index(const std::string& name) {
  static const char* voigt[6] = {"xx", "yy", "zz", "yz", "xz", "xy"};
  for (int k = 0; k < 6; ++k)
    if (name == voigt[k]) return k;
  if (name == "x") return 0;
  if (name == "y") return 1;
  if (name == "z") return 2;
  if (name == "magnitude") return -1;
  try {
    std::size_t used = 0;
    const int k = std::stoi(name, &used);
    if (used == name.size() && k >= -1) return k;
  } catch (const std::logic_error&) {
  }
  throw InputError(
      "--component",
      "expected xx, yy, zz, yz, xz, xy, x, y, z, magnitude or an index, got '" + name + "'");
}

Profile make_profile(const Frame& frame, int dim, const ProfileOptions& o) {
  const ColumnStore& cols = frame.columns;
  const Column* xc = cols.find("x");
  if (!xc) throw InputError("profile", "frames need the column 'x'");
  Profile p;
  p.time = frame.time;
  const std::function<double(std::size_t)> value = field_values(frame, o, p);
  const bool by_mass = o.weight == ProfileWeight::Mass;
  const ProfiledParticles pp{
      xc, cols.find("body"), cols.find("m"), cols.find("rho"), dim, o.body, by_mass};
  if (by_mass && !pp.mc && !o.on_grid)
    throw InputError("--weight", "mass weights need the column 'm', which the frames lack");
  if (o.body >= 0 && !pp.body) throw InputError("--body", "the frames hold no column 'body'");

  // The line: as given, or along the axis over the particles' extent through their centroid.
  if (o.from && o.to) {
    p.from = *o.from;
    p.to = *o.to;
  } else {
    default_line(frame, pp, o.axis, p);
  }
  const Vec3 d = p.to - p.from;
  const double length = d.norm();
  if (!(length > 0)) throw InputError("--to", "the line has no length");
  const ProfileLine line{p.from, d / length, length, o.radius};

  std::vector<Row> rows =
      o.on_grid ? grid_rows(frame, pp, value, line, o) : particle_rows(frame, pp, value, line);
  std::stable_sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) { return a.s < b.s; });
  if (o.bins <= 0) {
    for (const Row& r : rows) {
      p.s.push_back(r.s);
      p.value.push_back(r.v);
      p.weight.push_back(r.w);
    }
    return p;
  }
  bin_rows(rows, length, o.bins, p);
  return p;
}

}  // namespace mpm
