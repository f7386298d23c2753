// Bodies to particles: the parallel voxeliser. A plan per body (its cells and candidate
// points), a first pass that tests the points and keeps a bit per kept point, a second pass
// that writes the particles at their prefix-sum offsets, and the reports. Regions live in
// region.cpp (primitives) and mesh_region.cpp (meshes, CGAL).
#include "mpm/prep/voxelise.hpp"

#include <omp.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include "mpm/core/error.hpp"
#include "mpm/core/units.hpp"
#include "mpm/prep/body_placement.hpp"
#include "mpm/prep/mesh_region.hpp"
#include "mpm/prep/region.hpp"
#include "mpm/scene/particles.hpp"

namespace mpm {

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

/// The bodies' regions with their bounding boxes (blo, bhi; z = 0 in 2D).
struct BodyRegions {
  std::vector<std::unique_ptr<Region>> region;
  std::vector<Vec3> blo, bhi;
};

/// Density of a body's particles; rigid bodies carry a nominal 1 kg/m^3 (their mass is their
/// volume and takes no part in the dynamics).
double density_of(const Scene& scene, const BodySpec& body) {
  return body.rigid ? 1.0 : scene.materials[body.material].density;
}

/// At least one body.
void check_body_count(const Scene& scene) {
  if (scene.bodies.empty())
    throw InputError(where(scene.source, 0, "bodies"), "the scene has no bodies");
}

/// What a body needs besides its shape (make_region checks that): a valid material with a
/// positive density, 1 to 16 particles per cell, a finite velocity.
void check_body(const Scene& scene, const BodySpec& body) {
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
                     "the density must be positive, in kg/m^3 (got " + format_g6(rho) + ")");
  if (body.particle_spacing <= 0 && (body.particles_per_cell < 1 || body.particles_per_cell > 16))
    throw InputError(body_where(scene, body, "particles_per_cell"),
                     "particles per cell (per axis) must be 1 to 16 (got " +
                         std::to_string(body.particles_per_cell) + ")");
  if (!body.velocity.allFinite())
    throw InputError(body_where(scene, body, "velocity"), "the velocity must be finite");
}

/// The bodies' regions: every body is checked and every mesh read before any long work.
BodyRegions make_regions(const Scene& scene, int dim) {
  const std::size_t nb = scene.bodies.size();
  BodyRegions r;
  r.blo.resize(nb);
  r.bhi.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    const BodySpec& body = scene.bodies[b];
    check_body(scene, body);
    r.region.push_back(make_region(body, scene));
    r.region.back()->bounds(r.blo[b], r.bhi[b]);
    if (dim == 2) r.blo[b].z() = r.bhi[b].z() = 0;
  }
  return r;
}

/// The error for a body without particles: all its `skipped` points lie inside earlier
/// bodies, or (none skipped) it misses the domain or is thinner than its spacing s (m).
InputError no_particles(const Scene& scene, const BodySpec& body, double s, std::size_t skipped) {
  if (skipped > 0)
    return InputError(body_where(scene, body, ""),
                      "body '" + body.name + "' has no particles: all its " +
                          std::to_string(skipped) + " lattice points lie inside earlier bodies");
  return InputError(body_where(scene, body, ""),
                    "body '" + body.name +
                        "' has no particles: it lies outside the domain or is thinner than "
                        "a particle spacing (" +
                        format_g6(s) + " m)");
}

/// The cells [c0, c1) of the body's box [lo, hi] (m), clipped to the lattice; false when
/// they are empty along an axis.
bool plan_cells(BodyPlan& P, const Lattice& lat, const Vec3& lo, const Vec3& hi) {
  const int dim = lat.dim;
  const double h = lat.h;
  bool empty = false;
  for (int a = 0; a < 3; ++a) {
    if (a >= dim) {
      P.c0[a] = 0;
      P.c1[a] = 1;
      continue;
    }
    const double cells = lat.cells[a];
    const double f0 = std::floor((lo[a] - lat.origin[a]) / h);
    const double f1 = std::ceil((hi[a] - lat.origin[a]) / h);
    P.c0[a] = static_cast<long long>(std::clamp(f0, 0.0, cells));
    P.c1[a] = static_cast<long long>(std::clamp(f1, 0.0, cells));
    if (P.c1[a] <= P.c0[a]) empty = true;
  }
  return !empty;
}

/// Tabulates the candidate points along axis a of a body with box [lo, hi] (m), once, so both
/// passes use bit-identical values. particles_per_cell: cell corner + (i + 1/2) h / n, n in
/// every cell. particle_spacing: a lattice centred on the body's bounding box, round(L / s)
/// points along an extent L (at least one), so a box whose edges are multiples of s is tiled
/// exactly and a sphere's lattice is symmetric about its centre; each point belongs to the
/// cell it lies in. Returns the most points of one cell along the axis, 0 when it has none.
long long plan_axis(BodyPlan& P, int a, const Lattice& lat, const BodySpec& body, const Vec3& lo,
                    const Vec3& hi) {
  const int dim = lat.dim;
  const double h = lat.h;
  const double s = P.spacing;
  const long long m = a < dim ? P.c1[a] - P.c0[a] : 1;
  auto& at = P.at[a];
  auto& first = P.first[a];
  at.clear();
  first.assign(std::size_t(m) + 1, 0);
  if (a >= dim) {
    at.push_back(0.0);
    first[1] = 1;
    return 1;
  }
  if (body.particle_spacing <= 0) {
    const int n = body.particles_per_cell;
    for (long long c = 0; c < m; ++c) {
      for (int i = 0; i < n; ++i)
        at.push_back(lat.origin[a] + h * double(P.c0[a] + c) + (i + 0.5) * s);
      first[std::size_t(c) + 1] = (c + 1) * n;
    }
    return n;
  }
  const double extent = hi[a] - lo[a];
  const double centre = 0.5 * (lo[a] + hi[a]);
  const long long points = std::max(1LL, std::llround(extent / s));
  const double x0 = centre - 0.5 * double(points - 1) * s;
  for (long long i = 0; i < points; ++i) {
    const double x = x0 + double(i) * s;
    const double c = std::floor((x - lat.origin[a]) / h) - double(P.c0[a]);
    if (c < 0 || c >= double(m)) continue;  // outside the domain
    at.push_back(x);
    ++first[std::size_t(c) + 1];
  }
  long long most = 1;
  for (long long c = 0; c < m; ++c) {
    most = std::max(most, first[std::size_t(c) + 1]);
    first[std::size_t(c) + 1] += first[std::size_t(c)];
  }
  return at.empty() ? 0 : most;
}

/// Plans a body with box [lo, hi] (m): its spacing and particle mass, its cells, its candidate
/// points and its rows of bits. Returns false when it has no candidate point.
bool plan_body(BodyPlan& P, const Scene& scene, const BodySpec& body, const Lattice& lat,
               const Vec3& lo, const Vec3& hi) {
  const int dim = lat.dim;
  const double s = body.spacing(lat.h);
  P.spacing = s;
  P.particle_volume = dim == 3 ? s * s * s : s * s * 1.0;  // 2D: 1 m thick (or per radian, times r)
  P.mass = density_of(scene, body) * P.particle_volume;
  if (!plan_cells(P, lat, lo, hi)) return false;
  std::array<long long, 3> most{1, 1, 1};  // most points of one cell along each axis
  for (int a = 0; a < 3; ++a) {
    most[a] = plan_axis(P, a, lat, body, lo, hi);
    if (most[a] == 0) return false;
  }
  P.ny = P.c1[1] - P.c0[1];
  P.rows = P.ny * (P.c1[2] - P.c0[2]);
  // Row r's points in output order: cell x, then the points of the cell (z slowest, then y,
  // x); the cell at ix starts at first_x[ix] * (points of the row's cell along y and z).
  const long long row_points = static_cast<long long>(P.at[0].size()) * most[1] * most[2];
  P.words = (row_points + 63) / 64;
  const double candidates = double(P.rows) * double(P.words) * 64.0;
  if (candidates > std::ldexp(1.0, 38))
    throw InputError(body_where(scene, body, ""),
                     "body '" + body.name + "' spans " + format_count(candidates) +
                         " lattice points; a model holds at most 4294967295 particles");
  P.bits.assign(std::size_t(P.rows * P.words), 0);
  return true;
}

/// Pass 1 over one body's rows: tests the candidate points against the body's region and the
/// earlier bodies whose boxes meet its own (a point inside one of them is theirs, skipped), and
/// sets a bit per kept point.
class FirstPass {
 public:
  FirstPass(BodyPlan& P, std::size_t b, const Lattice& lat, const VoxeliseCells& cells,
            const BodyRegions& bodies)
      : P_(P),
        lat_(lat),
        cells_(cells),
        bodies_(bodies),
        region_(*bodies.region[b]),
        mesh_(dynamic_cast<const MeshRegion*>(&region_)) {
    const auto& blo = bodies.blo;
    const auto& bhi = bodies.bhi;
    for (std::size_t j = 0; j < b; ++j)
      if ((blo[j].array() <= bhi[b].array()).all() && (bhi[j].array() >= blo[b].array()).all())
        earlier_.push_back(j);
  }

  /// Tests row r; sets its bits and counts the points it keeps and skips.
  void row(long long r, std::uint64_t& kept_out, std::uint64_t& skipped_out) const;

 private:
  /// True when x lies inside an earlier body.
  bool taken(const Vec3& x) const {
    for (std::size_t j : earlier_)
      if ((x.array() >= bodies_.blo[j].array()).all() &&
          (x.array() <= bodies_.bhi[j].array()).all() && bodies_.region[j]->contains(x))
        return true;
    return false;
  }

  BodyPlan& P_;
  const Lattice& lat_;
  const VoxeliseCells& cells_;
  const BodyRegions& bodies_;
  const Region& region_;
  const MeshRegion* mesh_;            // the region when it is a mesh: rows are bisected
  std::vector<std::size_t> earlier_;  // earlier bodies whose boxes meet this one's
};

void FirstPass::row(long long r, std::uint64_t& kept_out, std::uint64_t& skipped_out) const {
  BodyPlan& P = P_;
  const double h = lat_.h;
  const long long ncx = P.c1[0] - P.c0[0];
  const long long iy = r % P.ny, iz = r / P.ny;
  const long long y0i = P.first[1][std::size_t(iy)], cy = P.count(1, iy);
  const long long z0i = P.first[2][std::size_t(iz)], cz = P.count(2, iz);
  std::uint64_t* w = P.bits.data() + r * P.words;
  std::uint64_t kept = 0, skipped = 0;
  // known = 1: the cell is wholly inside the region (only earlier bodies are tested).
  const auto test_cell = [&](long long ix, int known) {
    if (cells_.keep && !cells_.keep({P.c0[0] + ix, P.c0[1] + iy, P.c0[2] + iz})) return;
    const long long x0i = P.first[0][std::size_t(ix)], cx = P.count(0, ix);
    std::uint64_t idx = std::uint64_t(x0i * cy * cz);
    for (long long pz = 0; pz < cz; ++pz) {
      const double z = P.at[2][std::size_t(z0i + pz)];
      for (long long py = 0; py < cy; ++py) {
        const double y = P.at[1][std::size_t(y0i + py)];
        for (long long px = 0; px < cx; ++px, ++idx) {
          const Vec3 x(P.at[0][std::size_t(x0i + px)], y, z);
          if (known != 1 && !region_.contains(x)) continue;
          if (taken(x)) {
            ++skipped;
            continue;
          }
          w[idx >> 6] |= std::uint64_t(1) << (idx & 63);
          ++kept;
        }
      }
    }
  };
  if (mesh_) {
    // Bisect the row: boxes of cells the surface misses are wholly in or out, so only
    // the cells the surface cuts are tested point by point.
    const double y0 = lat_.origin[1] + h * double(P.c0[1] + iy);
    const double z0 = lat_.origin[2] + h * double(P.c0[2] + iz);
    const double z_step = lat_.dim == 3 ? h : 0.0;
    const auto corner_x = [&](long long ix) { return lat_.origin[0] + h * double(P.c0[0] + ix); };
    const auto segment = [&](auto&& self, long long a, long long e) -> void {
      const int side =
          mesh_->classify_box(Vec3(corner_x(a), y0, z0), Vec3(corner_x(e), y0 + h, z0 + z_step));
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
  kept_out = kept;
  skipped_out = skipped;
}

/// Pass 1 for body b: its bits, the prefix sums of its rows' kept points, kept and skipped.
void count_body(BodyPlan& P, std::size_t b, const Lattice& lat, const VoxeliseCells& cells,
                const BodyRegions& bodies) {
  const FirstPass pass(P, b, lat, cells, bodies);
  std::vector<std::uint64_t> row_kept(std::size_t(P.rows), 0), row_skipped(std::size_t(P.rows), 0);
  // In about a hundred slices of rows, to report progress between them (rows are independent:
  // the slices change nothing in the result).
  const long long slice = cells.progress ? std::max(1LL, P.rows / 100) : std::max(1LL, P.rows);
  for (long long r0 = 0; r0 < P.rows; r0 += slice) {
    const long long r1 = std::min(P.rows, r0 + slice);
#pragma omp parallel for schedule(dynamic, 8)
    for (long long r = r0; r < r1; ++r)
      pass.row(r, row_kept[std::size_t(r)], row_skipped[std::size_t(r)]);
    if (cells.progress) cells.progress(b, double(r1) / double(P.rows));
  }
  P.row_start.assign(std::size_t(P.rows) + 1, 0);
  for (long long r = 0; r < P.rows; ++r) {
    P.row_start[std::size_t(r) + 1] = P.row_start[std::size_t(r)] + row_kept[std::size_t(r)];
    P.skipped += row_skipped[std::size_t(r)];
  }
  P.kept = P.row_start.back();
}

/// The model's columns (voxelise.hpp), as pointers into the store.
struct ModelColumns {
  std::uint32_t* id;
  std::uint8_t* body8;    // up to 255 bodies (body_column)
  std::uint32_t* body32;  // more
  std::uint8_t* material;
  double* x;
  double* v;
  double* mass;
  double* rho;
};

/// The store of `total` particles with the model's columns.
ColumnStore model_store(int dim, std::size_t total, std::size_t bodies) {
  ColumnStore store;
  store.add({"id", ScalarType::U32, 1, "-"});
  store.add(body_column(bodies));
  store.add({"material", ScalarType::U8, 1, "-"});
  store.add({"x", ScalarType::F64, dim, "m"});
  store.add({"v", ScalarType::F64, dim, "m/s"});
  store.add({"m", ScalarType::F64, 1, "kg"});
  store.add({"rho", ScalarType::F64, 1, "kg/m^3"});
  store.resize(total);
  return store;
}

ModelColumns model_columns(ColumnStore& store) {
  const bool narrow = store.at("body").info().type == ScalarType::U8;
  return {store.get<std::uint32_t>("id"),
          narrow ? store.get<std::uint8_t>("body") : nullptr,
          narrow ? nullptr : store.get<std::uint32_t>("body"),
          store.get<std::uint8_t>("material"),
          reinterpret_cast<double*>(store.at("x").data()),
          reinterpret_cast<double*>(store.at("v").data()),
          store.get<double>("m"),
          store.get<double>("rho")};
}

/// Pass 2 for body b: writes the particles of its kept points, from particle `base` on, row
/// by row at the rows' prefix-sum offsets.
void write_body(const BodyPlan& P, const Scene& scene, std::size_t b, int dim, std::size_t base,
                const ModelColumns& col) {
  const BodySpec& body = scene.bodies[b];
  const double density = density_of(scene, body);
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
      for (std::uint64_t word = w[wi]; word; word &= word - 1, ++k) {
        const std::uint64_t idx = std::uint64_t(wi) * 64 + std::uint64_t(std::countr_zero(word));
        while (std::uint64_t(first_x[ix + 1]) * per_x <= idx) ++ix;
        const long long cx = first_x[ix + 1] - first_x[ix];
        const long long p = static_cast<long long>(idx - std::uint64_t(first_x[ix]) * per_x);
        const long long px = p % cx, py = (p / cx) % cy, pz = p / (cx * cy);
        double* x = col.x + k * dim;
        double* v = col.v + k * dim;
        x[0] = P.at[0][std::size_t(first_x[ix] + px)];
        x[1] = P.at[1][std::size_t(y0i + py)];
        v[0] = body.velocity.x();
        v[1] = body.velocity.y();
        if (dim == 3) {
          x[2] = P.at[2][std::size_t(z0i + pz)];
          v[2] = body.velocity.z();
        }
        col.id[k] = static_cast<std::uint32_t>(k);
        if (col.body8)
          col.body8[k] = static_cast<std::uint8_t>(b);
        else
          col.body32[k] = static_cast<std::uint32_t>(b);
        col.material[k] = mat_id;
        col.mass[k] = axi ? P.mass * x[0] : P.mass;  // axisymmetric: per radian, A r
        col.rho[k] = density;
      }
    }
  }
}

/// The report of body b, whose particles are the P.kept before `end`.
BodyReport report_body(const BodyPlan& P, const Scene& scene, std::size_t b, const Region& region,
                       const double* mass, std::size_t end) {
  BodyReport rep;
  rep.name = scene.bodies[b].name;
  rep.particles = P.kept;
  rep.mass = 0;
  for (std::size_t k = end - P.kept; k < end; ++k) rep.mass += mass[k];
  // 2D: area x 1 m; axisymmetric: per radian, the part at r >= 0 (a body may cross the axis:
  // a disk centred on it is a sphere).
  const double density = density_of(scene, scene.bodies[b]);
  rep.exact_mass = density * (scene.axisymmetric ? region.revolved_volume() : region.volume());
  rep.spacing = P.spacing;
  rep.finest_spacing = P.spacing;
  rep.skipped_overlap = P.skipped;
  return rep;
}

}  // namespace

ColumnStore voxelise(const Scene& scene, const Lattice& lat, std::vector<BodyReport>& report,
                     const VoxeliseCells& cells) {
  report.clear();
  const int dim = lat.dim;
  if (dim != 2 && dim != 3) throw std::logic_error("voxelise: lattice dimension must be 2 or 3");
  check_body_count(scene);
  const std::size_t nb = scene.bodies.size();
  const BodyRegions bodies = make_regions(scene, dim);

  // Pass 1, body by body: test every candidate point, keep a bit per kept point.
  std::vector<BodyPlan> plans(nb);
  std::size_t total = 0;
  for (std::size_t b = 0; b < nb; ++b) {
    const BodySpec& body = scene.bodies[b];
    BodyPlan& P = plans[b];
    if (!plan_body(P, scene, body, lat, bodies.blo[b], bodies.bhi[b])) {
      if (cells.allow_empty) continue;  // nothing of this body in these cells
      throw no_particles(scene, body, P.spacing, 0);
    }
    count_body(P, b, lat, cells, bodies);
    if (P.kept == 0 && !cells.allow_empty) throw no_particles(scene, body, P.spacing, P.skipped);
    total += P.kept;
    if (total > std::numeric_limits<std::uint32_t>::max())
      throw InputError(body_where(scene, body, ""),
                       "the bodies up to '" + body.name + "' make " + std::to_string(total) +
                           " particles; a model holds at most 4294967295 (ids are 32-bit)");
  }

  // Pass 2: fill the columns, every body's rows at their prefix-sum offsets.
  ColumnStore store = model_store(dim, total, nb);
  const ModelColumns col = model_columns(store);
  std::size_t base = 0;
  for (std::size_t b = 0; b < nb; ++b) {
    write_body(plans[b], scene, b, dim, base, col);
    base += plans[b].kept;
    report.push_back(report_body(plans[b], scene, b, *bodies.region[b], col.mass, base));
  }
  return store;
}

}  // namespace mpm
