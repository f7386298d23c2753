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

namespace mpm {

namespace {

/// Value of component k of element i of a floating column.
double value_at(const Column& c, std::size_t i, int k) {
  const int nc = c.info().components;
  if (c.info().type == ScalarType::F64)
    return reinterpret_cast<const double*>(c.data())[i * nc + k];
  if (c.info().type == ScalarType::F32) return reinterpret_cast<const float*>(c.data())[i * nc + k];
  if (c.info().type == ScalarType::U8)
    return reinterpret_cast<const std::uint8_t*>(c.data())[i * nc + k];
  if (c.info().type == ScalarType::U32)
    return reinterpret_cast<const std::uint32_t*>(c.data())[i * nc + k];
  if (c.info().type == ScalarType::I32)
    return reinterpret_cast<const std::int32_t*>(c.data())[i * nc + k];
  return double(reinterpret_cast<const std::uint64_t*>(c.data())[i * nc + k]);
}

std::string available(const Frame& f) {
  std::string s;
  for (const Column& c : f.columns.columns())
    if (c.info().name != "x") s += (s.empty() ? "" : ", ") + c.info().name;
  return s + ", pressure, von_mises, speed";
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
  const std::size_t n = cols.size();
  auto pos = [&](std::size_t i) {
    Vec3 x = Vec3::Zero();
    for (int a = 0; a < dim; ++a) x[a] = value_at(*xc, i, a);
    return x;
  };
  // The field: a column (component or magnitude) or a derived one.
  Profile p;
  p.time = frame.time;
  std::function<double(std::size_t)> value;
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
      value = [c, k](std::size_t i) { return value_at(*c, i, k); };
    } else {
      value = [c, nc](std::size_t i) {
        double s = 0;
        for (int k = 0; k < nc; ++k) s += value_at(*c, i, k) * value_at(*c, i, k);
        return std::sqrt(s);
      };
    }
  } else if ((o.field == "pressure" || o.field == "von_mises") && sig) {
    p.unit = sig->info().unit;
    const bool pressure = o.field == "pressure";
    value = [sig, pressure](std::size_t i) {
      Sym s;
      for (int k = 0; k < 6; ++k) s[k] = value_at(*sig, i, k);
      return pressure ? -trace(s) / 3.0 : von_mises(s);
    };
  } else if (o.field == "speed" && cols.find("v")) {
    const Column* v = cols.find("v");
    p.unit = v->info().unit;
    value = [v](std::size_t i) {
      double s = 0;
      for (int k = 0; k < v->info().components; ++k) s += value_at(*v, i, k) * value_at(*v, i, k);
      return std::sqrt(s);
    };
  } else {
    throw InputError("--field",
                     "unknown field '" + o.field + "' (available: " + available(frame) + ")");
  }
  const Column* body = cols.find("body");
  if (o.body >= 0 && !body) throw InputError("--body", "the frames hold no column 'body'");
  auto selected = [&](std::size_t i) { return o.body < 0 || value_at(*body, i, 0) == o.body; };
  const Column* mc = cols.find("m");
  const Column* rc = cols.find("rho");
  auto weight = [&](std::size_t i) {
    return mc && rc ? value_at(*mc, i, 0) / value_at(*rc, i, 0) : 1.0;
  };

  // The line: as given, or along the axis over the particles' extent through their centroid.
  if (o.from && o.to) {
    p.from = *o.from;
    p.to = *o.to;
  } else {
    Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300), c = Vec3::Zero();
    std::size_t k = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!selected(i)) continue;
      const Vec3 x = pos(i);
      lo = lo.cwiseMin(x), hi = hi.cwiseMax(x), c += x, ++k;
    }
    if (k == 0)
      throw InputError("profile", "no particle to profile in the frame at t = " +
                                      std::to_string(frame.time) + " s");
    c /= double(k);
    p.from = c, p.to = c;
    p.from[o.axis] = lo[o.axis];
    p.to[o.axis] = hi[o.axis];
  }
  const Vec3 d = p.to - p.from;
  const double length = d.norm();
  if (!(length > 0)) throw InputError("--to", "the line has no length");
  const Vec3 e = d / length;

  struct Row {
    double s, v, w;
  };
  std::vector<Row> rows;
  auto near = [&](const Vec3& x, double& s) {
    const Vec3 r = x - p.from;
    s = r.dot(e);
    return s >= -1e-12 * length && s <= length * (1 + 1e-12) &&
           (r - s * e).norm() <= o.radius * (1 + 1e-12);
  };
  if (o.on_grid) {
    // Particle to grid with the solver's linear shape functions, mass-weighted.
    if (!(o.cell > 0)) throw InputError("--grid", "the grid's cell size is unknown");
    std::map<std::array<long, 3>, std::pair<double, double>> nodes;  // (sum w m v, sum w m)
    for (std::size_t i = 0; i < n; ++i) {
      if (!selected(i)) continue;
      const Vec3 xi = (pos(i) - o.origin) / o.cell;
      std::array<long, 3> c{0, 0, 0};
      Vec3 f = Vec3::Zero();
      for (int a = 0; a < dim; ++a) c[a] = long(std::floor(xi[a])), f[a] = xi[a] - double(c[a]);
      const double m = mc ? value_at(*mc, i, 0) : 1.0, v = value(i);
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
    for (const auto& [k, acc] : nodes) {
      if (!(acc.second > 0)) continue;
      Vec3 x = o.origin;
      for (int a = 0; a < dim; ++a) x[a] += double(k[a]) * o.cell;
      double s;
      if (near(x, s)) rows.push_back({s, acc.first / acc.second, acc.second});
    }
    if (rows.empty())
      throw InputError("profile",
                       "no grid node with mass lies within --radius of the line at t = " +
                           std::to_string(frame.time) + " s (nodes are " + std::to_string(o.cell) +
                           " m apart)");
  } else {
    for (std::size_t i = 0; i < n; ++i) {
      double s;
      if (selected(i) && near(pos(i), s)) rows.push_back({s, value(i), weight(i)});
    }
    if (rows.empty())
      throw InputError("profile", "no particle lies within --radius of the line at t = " +
                                      std::to_string(frame.time) + " s");
  }
  std::stable_sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) { return a.s < b.s; });
  if (o.bins <= 0) {
    for (const Row& r : rows) {
      p.s.push_back(r.s);
      p.value.push_back(r.v);
      p.weight.push_back(r.w);
    }
    return p;
  }
  const double width = length / o.bins;
  p.s.resize(o.bins);
  p.value.assign(o.bins, 0.0);
  p.weight.assign(o.bins, 0.0);
  p.min.assign(o.bins, std::numeric_limits<double>::quiet_NaN());
  p.max.assign(o.bins, std::numeric_limits<double>::quiet_NaN());
  p.count.assign(o.bins, 0);
  for (int b = 0; b < o.bins; ++b) p.s[b] = (b + 0.5) * width;
  for (const Row& r : rows) {
    const int b = std::clamp(int(r.s / width), 0, o.bins - 1);
    p.value[b] += r.w * r.v;
    p.weight[b] += r.w;
    p.min[b] = p.count[b] ? std::min(p.min[b], r.v) : r.v;
    p.max[b] = p.count[b] ? std::max(p.max[b], r.v) : r.v;
    ++p.count[b];
  }
  for (int b = 0; b < o.bins; ++b)
    p.value[b] =
        p.weight[b] > 0 ? p.value[b] / p.weight[b] : std::numeric_limits<double>::quiet_NaN();
  return p;
}

}  // namespace mpm
