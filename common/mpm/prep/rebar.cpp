#include "mpm/prep/rebar.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "mpm/core/error.hpp"
#include "mpm/core/units.hpp"
#include "mpm/scene/particles.hpp"
#include "mpm/scene/rebar_elements.hpp"

namespace mpm {

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string key_of(const RebarSpec& b, const std::string& key) {
  return b.loc.key + "." + key;
}
[[noreturn]] void fail(const RebarSpec& b, const std::string& key, const std::string& message) {
  throw InputError(where(b.loc.file, b.loc.line, key_of(b, key)), message);
}

/// The polylines of a file: x y z (m) per line, '#' comments, blank lines between polylines.
std::vector<std::vector<Vec3>> read_polylines(const Scene& scene, const RebarSpec& b) {
  namespace fs = std::filesystem;
  const fs::path p = fs::path(b.path).is_absolute() || scene.directory.empty()
                         ? fs::path(b.path)
                         : fs::path(scene.directory) / b.path;
  std::error_code ec;
  if (fs::is_directory(p, ec)) fail(b, "file", "'" + p.string() + "' is a directory");
  std::ifstream in(p);
  if (!in) fail(b, "file", "cannot read '" + p.string() + "': " + std::strerror(errno));
  std::vector<std::vector<Vec3>> lines(1);
  std::string text;
  int line_no = 0;
  while (std::getline(in, text)) {
    ++line_no;
    const std::string body = text.substr(0, text.find('#'));
    std::istringstream s(body);
    Vec3 x;
    if (!(s >> x[0])) {  // blank (or comment only): ends a polyline
      std::string rest;
      if (std::istringstream(body) >> rest)
        throw InputError(where(p.string(), line_no, ""),
                         "expected three numbers x y z in metres, got '" + body + "'");
      if (!lines.back().empty()) lines.emplace_back();
      continue;
    }
    std::string junk;
    if (!(s >> x[1] >> x[2]) || (s >> junk) || !x.allFinite())
      throw InputError(where(p.string(), line_no, ""),
                       "expected three numbers x y z in metres, got '" + body + "'");
    lines.back().push_back(x);
  }
  if (in.bad()) fail(b, "file", "read error in '" + p.string() + "'");
  if (lines.back().empty()) lines.pop_back();
  for (const auto& l : lines)
    if (l.size() < 2) fail(b, "file", "'" + p.string() + "': a polyline needs at least two points");
  if (lines.empty()) fail(b, "file", "'" + p.string() + "' holds no polyline");
  return lines;
}

/// The bars of a square-pattern layer across the body's box (clipped to the domain).
std::vector<std::vector<Vec3>> layer_lines(const RebarSpec& b, const Vec3& body_lo,
                                           const Vec3& body_hi, const Lattice& lattice) {
  const int n = b.normal, ax[2] = {(n + 1) % 3, (n + 2) % 3};
  const Vec3 lo = body_lo.cwiseMax(lattice.origin), hi = body_hi.cwiseMin(lattice.max());
  const double r = 0.5 * b.diameter;
  const double plane = b.offset_given     ? b.offset
                       : b.cover_from_max ? body_hi[n] - b.cover - r
                                          : body_lo[n] + b.cover + r;
  std::vector<std::vector<Vec3>> lines;
  for (int f = 0; f < 2; ++f) {  // family f: bars parallel to ax[f], spaced along ax[1 - f]
    const int along = ax[f], across = ax[1 - f];
    const double first = b.first_given ? b.first[1 - f]
                                       : 0.5 * (body_lo[across] + body_hi[across]) -
                                             0.5 * (b.count[f] - 1) * b.pitch;
    for (int k = 0; k < b.count[f]; ++k) {
      Vec3 a, e;
      a[n] = e[n] = plane;
      a[across] = e[across] = first + k * b.pitch;
      a[along] = lo[along];
      e[along] = hi[along] - 1e-9 * lattice.h;  // the domain's upper face is outside it
      lines.push_back({a, e});
    }
  }
  return lines;
}

/// Fails unless x lies in the domain [origin, max).
void check_in_domain(const RebarSpec& b, const Lattice& lattice, const Vec3& x,
                     const std::string& key) {
  const Vec3 lo = lattice.origin, hi = lattice.max();
  for (int a = 0; a < 3; ++a)
    if (!(x[a] >= lo[a] && x[a] < hi[a]))
      fail(b, key,
           "the bar leaves the domain at (" + format_mm(x[0]) + ", " + format_mm(x[1]) + ", " +
               format_mm(x[2]) + ") mm; the domain is [" + format_mm(lo[0]) + ", " +
               format_mm(hi[0]) + "] x [" + format_mm(lo[1]) + ", " + format_mm(hi[1]) + "] x [" +
               format_mm(lo[2]) + ", " + format_mm(hi[2]) + "] mm");
}

/// The share of a bar's section in the model: a half for each symmetry plane (a slip face of
/// the domain) the whole bar lies in, so that a quarter model's bar on a mirror plane carries
/// half its steel, as its particles there carry half their cell.
double section_share(const std::vector<Vec3>& line, const Scene& scene, const Lattice& lattice) {
  double share = 1;
  for (int f = 0; f < 6; ++f) {
    if (scene.boundary.face[f] != BoundaryType::Slip) continue;
    const int a = f / 2;
    const double plane = f % 2 ? lattice.max()[a] : lattice.origin[a];
    bool on = true;
    for (const Vec3& x : line) on = on && std::abs(x[a] - plane) <= 1e-9 * lattice.h;
    if (on) share *= 0.5;
  }
  return share;
}

/// Node particles appended to the model's columns.
struct NodeSink {
  ColumnStore& cols;
  std::vector<Vec3> x;
  std::vector<double> m;
  std::vector<int> body;
  std::vector<Vec3> v;
  std::vector<double> rho;
  std::uint32_t add(const Vec3& p, int b, const Vec3& vel, double density, std::uint32_t first_id) {
    x.push_back(p), m.push_back(0.0), body.push_back(b), v.push_back(vel), rho.push_back(density);
    return first_id + std::uint32_t(x.size() - 1);
  }
};

struct ElementRows {
  std::vector<std::uint32_t> nodes, bar;
  std::vector<std::uint8_t> material;
  std::vector<double> area, length0;
};

}  // namespace

std::vector<std::vector<Vec3>> rebar_lines(const Scene& scene, std::size_t entry, const Vec3& lo,
                                           const Vec3& hi, const Lattice& lattice) {
  const RebarSpec& b = scene.rebars[entry];
  switch (b.shape) {
    case RebarShape::Bar:
      return {{b.start, b.end}};
    case RebarShape::Layer:
      return layer_lines(b, lo, hi, lattice);
    case RebarShape::Polyline:
      return read_polylines(scene, b);
  }
  return {};
}

ColumnStore discretise_rebar(const Scene& scene, const Lattice& lattice,
                             const std::vector<Vec3>& body_lo, const std::vector<Vec3>& body_hi,
                             ColumnStore& cols, std::vector<RebarReport>& report) {
  std::uint32_t first_id = 0;
  if (const auto* id = cols.get<std::uint32_t>(col::id))
    for (std::size_t i = 0; i < cols.size(); ++i) first_id = std::max(first_id, id[i] + 1);
  NodeSink nodes{cols, {}, {}, {}, {}, {}};
  ElementRows rows;
  report.assign(scene.rebars.size(), {});
  for (std::size_t r = 0; r < scene.rebars.size(); ++r) {
    const RebarSpec& b = scene.rebars[r];
    const MaterialSpec& mat = scene.materials[b.material];
    const double A_bar = 0.25 * kPi * b.diameter * b.diameter, rho = mat.density;
    const double le = b.element_length > 0 ? b.element_length : 0.5 * lattice.h;
    const Vec3 vel = scene.bodies[b.body].velocity;
    RebarReport& rep = report[r];
    for (const auto& line : rebar_lines(scene, r, body_lo[b.body], body_hi[b.body], lattice)) {
      ++rep.bars;
      const std::string key = b.shape == RebarShape::Bar     ? "end"
                              : b.shape == RebarShape::Layer ? "pitch"
                                                             : "file";
      double total = 0;
      for (std::size_t s = 0; s < line.size(); ++s) {
        check_in_domain(b, lattice, line[s], key);
        if (s > 0) total += (line[s] - line[s - 1]).norm();
      }
      if (!(total > 0)) fail(b, key, "a bar of zero length");
      const double A = A_bar * section_share(line, scene, lattice);
      std::uint32_t prev = nodes.add(line[0], b.body, vel, rho, first_id);
      for (std::size_t s = 0; s + 1 < line.size(); ++s) {
        const Vec3 a = line[s], e = line[s + 1];
        const double L = (e - a).norm();
        if (!(L > 0)) continue;  // a repeated point
        const int ne = std::max(1, int(std::ceil(L / le * (1 - 1e-12))));
        for (int k = 1; k <= ne; ++k) {
          const Vec3 x = k == ne ? e : Vec3(a + (e - a) * (double(k) / ne));
          const std::uint32_t next = nodes.add(x, b.body, vel, rho, first_id);
          const double Le = (x - nodes.x[prev - first_id]).norm();
          nodes.m[prev - first_id] += 0.5 * rho * A * Le;  // lumped mass (004, eq. 11)
          nodes.m[next - first_id] += 0.5 * rho * A * Le;
          rows.nodes.insert(rows.nodes.end(), {prev, next});
          rows.bar.push_back(std::uint32_t(r));
          rows.material.push_back(std::uint8_t(b.material));
          rows.area.push_back(A);
          rows.length0.push_back(Le);
          rep.element_length = std::max(rep.element_length, Le);
          rep.shortest = rep.elements == 0 ? Le : std::min(rep.shortest, Le);
          ++rep.elements;
          prev = next;
        }
        rep.length += L;
        rep.exact_mass += rho * A * L;
      }
    }
  }
  // The node particles, after the model's.
  const std::size_t n0 = cols.size(), nn = nodes.x.size();
  cols.resize(n0 + nn);
  auto* id = cols.get<std::uint32_t>(col::id);
  auto* mat = cols.get<std::uint8_t>(col::material);
  auto* x = reinterpret_cast<double*>(cols.at(col::x).data());
  auto* v = reinterpret_cast<double*>(cols.at(col::v).data());
  auto* m = cols.get<double>(col::m);
  auto* rho = cols.get<double>(col::rho);
  Column& body = cols.at(col::body);
  for (std::size_t k = 0; k < nn; ++k) {
    const std::size_t i = n0 + k;
    id[i] = first_id + std::uint32_t(k);
    mat[i] = kRebarNode;
    for (int a = 0; a < 3; ++a) x[3 * i + a] = nodes.x[k][a], v[3 * i + a] = nodes.v[k][a];
    m[i] = nodes.m[k];
    rho[i] = nodes.rho[k];
    if (body.info().type == ScalarType::U32)
      body.as<std::uint32_t>()[i] = std::uint32_t(nodes.body[k]);
    else
      body.as<std::uint8_t>()[i] = std::uint8_t(nodes.body[k]);
  }
  // Nodes per entry: the nodes of its elements (a node belongs to one entry).
  std::vector<std::uint32_t> owner(nn, 0);
  for (std::size_t e = 0; e < rows.bar.size(); ++e)
    for (int j = 0; j < 2; ++j) owner[rows.nodes[2 * e + j] - first_id] = rows.bar[e];
  for (std::size_t k = 0; k < nn; ++k) ++report[owner[k]].nodes, report[owner[k]].mass += m[n0 + k];
  ColumnStore el = rebar_element_columns();
  el.resize(rows.bar.size());
  if (rows.bar.empty()) return el;  // no rebar: empty columns have no storage to copy into
  std::memcpy(el.at(rebar_col::nodes).data(), rows.nodes.data(), rows.nodes.size() * 4);
  std::memcpy(el.at(rebar_col::bar).data(), rows.bar.data(), rows.bar.size() * 4);
  std::memcpy(el.at(rebar_col::material).data(), rows.material.data(), rows.material.size());
  std::memcpy(el.at(rebar_col::area).data(), rows.area.data(), rows.area.size() * 8);
  std::memcpy(el.at(rebar_col::length0).data(), rows.length0.data(), rows.length0.size() * 8);
  return el;
}

}  // namespace mpm
