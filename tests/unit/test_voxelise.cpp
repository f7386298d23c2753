// Voxeliser: lattice fitting, primitive and mesh regions, particle columns.
#include <gtest/gtest.h>
#include <omp.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include "mpm/core/error.hpp"
#include "mpm/grid/lattice.hpp"
#include "mpm/prep/region.hpp"
#include "mpm/prep/voxelise.hpp"

namespace fs = std::filesystem;
using namespace mpm;

namespace {

constexpr double kPi = std::numbers::pi;

// ---------------------------------------------------------------------------------------------
// Scenes built directly (no parser in this module).

Scene make_scene(int dim, double h, const Vec3& lo, const Vec3& hi) {
  Scene s;
  s.source = "scene.toml";
  s.directory = "";
  s.dimension = dim;
  MaterialSpec steel;
  steel.name = "steel";
  steel.density = 7850;
  MaterialSpec al;
  al.name = "al";
  al.density = 2700;
  s.materials = {steel, al};
  s.grid.cell_size = h;
  s.grid.domain_given = true;
  s.grid.domain_min = lo;
  s.grid.domain_max = hi;
  s.grid.loc.line = 3;
  return s;
}

BodySpec make_body(const std::string& name, ShapeKind shape, int line = 10) {
  BodySpec b;
  b.name = name;
  b.material = 0;
  b.shape = shape;
  b.particles_per_cell = 2;
  b.loc.line = line;
  b.loc.key = "bodies." + name;
  return b;
}

BodySpec sphere(const std::string& name, double r, const Vec3& c) {
  BodySpec b = make_body(name, ShapeKind::Sphere);
  b.radius = r;
  b.translate = c;
  return b;
}

BodySpec cylinder(const std::string& name, double r, double length) {
  BodySpec b = make_body(name, ShapeKind::Cylinder);
  b.radius = r;
  b.length = length;
  return b;
}

BodySpec box(const std::string& name, const Vec3& size, const Vec3& c) {
  BodySpec b = make_body(name, ShapeKind::Box);
  b.size = size;
  b.translate = c;
  return b;
}

BodySpec mesh_body(const std::string& name, const std::string& path, int line = 20) {
  BodySpec b = make_body(name, ShapeKind::Mesh, line);
  b.mesh_path = path;
  return b;
}

struct Voxels {
  ColumnStore store;
  std::vector<BodyReport> report;
  Lattice lattice;
};

Voxels run(const Scene& s) {
  Voxels r;
  r.lattice = make_lattice(s);
  r.store = voxelise(s, r.lattice, r.report);
  return r;
}

double particle_volume(const Voxels& r, int n = 2) {
  const double sp = r.lattice.h / n;
  return r.lattice.dim == 3 ? sp * sp * sp : sp * sp;
}

/// Integer lattice-point index (i, j, k) of particle p: x = origin + (i + 1/2) h/n.
std::array<long long, 3> point_index(const Voxels& r, std::size_t p, int n = 2) {
  const int dim = r.lattice.dim;
  const double* x = reinterpret_cast<const double*>(r.store.at("x").data()) + p * dim;
  std::array<long long, 3> ijk{0, 0, 0};
  const double sp = r.lattice.h / n;
  for (int a = 0; a < dim; ++a) ijk[a] = std::llround((x[a] - r.lattice.origin[a]) / sp - 0.5);
  return ijk;
}

std::set<std::array<long long, 3>> point_set(const Voxels& r, std::size_t from, std::size_t to) {
  std::set<std::array<long long, 3>> s;
  for (std::size_t p = from; p < to; ++p) s.insert(point_index(r, p));
  return s;
}

Vec3 position(const Voxels& r, std::size_t p) {
  const int dim = r.lattice.dim;
  const double* x = reinterpret_cast<const double*>(r.store.at("x").data()) + p * dim;
  return Vec3(x[0], x[1], dim == 3 ? x[2] : 0.0);
}

/// Same columns, same bytes.
void expect_identical(const ColumnStore& a, const ColumnStore& b) {
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.columns().size(), b.columns().size());
  for (const Column& ca : a.columns()) {
    const Column& cb = b.at(ca.info().name);
    ASSERT_EQ(ca.bytes(), cb.bytes()) << ca.info().name;
    EXPECT_EQ(std::memcmp(ca.data(), cb.data(), ca.bytes()), 0) << "column " << ca.info().name;
  }
}

template <class F>
std::string input_error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

Mat3 rotation(const Vec3& deg) {
  const double k = kPi / 180;
  return (Eigen::AngleAxisd(k * deg.z(), Vec3::UnitZ()) *
          Eigen::AngleAxisd(k * deg.y(), Vec3::UnitY()) *
          Eigen::AngleAxisd(k * deg.x(), Vec3::UnitX()))
      .toRotationMatrix();
}

/// Local-frame coordinates of a world point for a body: S^-1 R^T (x - t).
Vec3 to_local(const BodySpec& b, const Vec3& x) {
  return b.scale.cwiseInverse().asDiagonal() *
         (rotation(b.rotate_deg).transpose() * (x - b.translate));
}

// ---------------------------------------------------------------------------------------------
// Triangle meshes generated here and written in every format.

struct TriMesh {
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> f;

  /// Signed volume (divergence theorem), m^3.
  double volume() const {
    double s = 0;
    for (auto& t : f) s += v[t[0]].dot(v[t[1]].cross(v[t[2]])) / 6.0;
    return s;
  }
  /// Smallest distance from the origin to a face's plane (the in-radius for a convex mesh
  /// around the origin).
  double min_plane_distance() const {
    double d = std::numeric_limits<double>::infinity();
    for (auto& t : f) {
      const Vec3 n = (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]).normalized();
      d = std::min(d, std::abs(n.dot(v[t[0]])));
    }
    return d;
  }
  /// Rounds vertices to float so that every format (binary STL stores float) holds the same
  /// coordinates; %.9g text round-trips a float exactly.
  void round_to_float() {
    for (auto& p : v)
      for (int a = 0; a < 3; ++a) p[a] = double(float(p[a]));
  }

  void write_ascii_stl(const fs::path& path) const {
    FILE* out = std::fopen(path.c_str(), "w");
    ASSERT_TRUE(out);
    std::fprintf(out, "solid test\n");
    for (auto& t : f) {
      const Vec3 n = (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]).normalized();
      std::fprintf(out, " facet normal %.9g %.9g %.9g\n  outer loop\n", n.x(), n.y(), n.z());
      for (int i : t) std::fprintf(out, "   vertex %.9g %.9g %.9g\n", v[i].x(), v[i].y(), v[i].z());
      std::fprintf(out, "  endloop\n endfacet\n");
    }
    std::fprintf(out, "endsolid test\n");
    std::fclose(out);
  }
  /// Binary STL. Some exporters start the 80-byte header with "solid", as ASCII files do.
  void write_binary_stl(const fs::path& path,
                        const char* title = "binary STL written by test_voxelise") const {
    std::ofstream out(path, std::ios::binary);
    char header[80] = {};
    std::snprintf(header, sizeof header, "%s", title);
    out.write(header, 80);
    const std::uint32_t count = static_cast<std::uint32_t>(f.size());
    out.write(reinterpret_cast<const char*>(&count), 4);
    for (auto& t : f) {
      const Vec3 n = (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]).normalized();
      float buf[12];
      for (int a = 0; a < 3; ++a) buf[a] = float(n[a]);
      for (int i = 0; i < 3; ++i)
        for (int a = 0; a < 3; ++a) buf[3 + 3 * i + a] = float(v[t[i]][a]);
      out.write(reinterpret_cast<const char*>(buf), sizeof buf);
      const std::uint16_t attr = 0;
      out.write(reinterpret_cast<const char*>(&attr), 2);
    }
  }
  void write_off(const fs::path& path) const {
    FILE* out = std::fopen(path.c_str(), "w");
    ASSERT_TRUE(out);
    std::fprintf(out, "OFF\n%zu %zu 0\n", v.size(), f.size());
    for (auto& p : v) std::fprintf(out, "%.9g %.9g %.9g\n", p.x(), p.y(), p.z());
    for (auto& t : f) std::fprintf(out, "3 %d %d %d\n", t[0], t[1], t[2]);
    std::fclose(out);
  }
  void write_obj(const fs::path& path) const {
    FILE* out = std::fopen(path.c_str(), "w");
    ASSERT_TRUE(out);
    std::fprintf(out, "# written by test_voxelise\n");
    for (auto& p : v) std::fprintf(out, "v %.9g %.9g %.9g\n", p.x(), p.y(), p.z());
    for (auto& t : f) std::fprintf(out, "f %d %d %d\n", t[0] + 1, t[1] + 1, t[2] + 1);
    std::fclose(out);
  }
};

/// Icosahedron subdivided `levels` times, vertices on the sphere of radius r about the origin.
TriMesh icosphere(double r, int levels) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  TriMesh m;
  m.v = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
         {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : m.v) p.normalize();
  m.f = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
         {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
         {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    const auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      m.v.push_back((m.v[a] + m.v[b]).normalized());
      return mid[key] = int(m.v.size()) - 1;
    };
    std::vector<std::array<int, 3>> next;
    for (auto& tri : m.f) {
      const int a = tri[0], b = tri[1], c = tri[2];
      const int ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      next.push_back({a, ab, ca});
      next.push_back({b, bc, ab});
      next.push_back({c, ca, bc});
      next.push_back({ab, bc, ca});
    }
    m.f = std::move(next);
  }
  for (auto& p : m.v) p *= r;
  m.round_to_float();
  return m;
}

/// Prism over a regular `segments`-gon inscribed in the circle of radius r, along +z from 0 to
/// length (the primitive cylinder's local frame); caps are fans around their centres.
TriMesh cylinder_mesh(double r, double length, int segments) {
  TriMesh m;
  for (int k = 0; k < segments; ++k) {
    const double a = 2 * kPi * k / segments;
    m.v.push_back({r * std::cos(a), r * std::sin(a), 0});
    m.v.push_back({r * std::cos(a), r * std::sin(a), length});
  }
  const int c0 = int(m.v.size()), c1 = c0 + 1;
  m.v.push_back({0, 0, 0});
  m.v.push_back({0, 0, length});
  for (int k = 0; k < segments; ++k) {
    const int b0 = 2 * k, t0 = 2 * k + 1, b1 = 2 * ((k + 1) % segments), t1 = b1 + 1;
    m.f.push_back({b0, b1, t1});
    m.f.push_back({b0, t1, t0});
    m.f.push_back({c0, b1, b0});
    m.f.push_back({c1, t0, t1});
  }
  m.round_to_float();
  return m;
}

/// Box centred at the origin, 12 outward triangles.
TriMesh box_mesh(const Vec3& size) {
  TriMesh m;
  const Vec3 h = size / 2;
  for (int k = 0; k < 8; ++k)
    m.v.push_back({(k & 1) ? h.x() : -h.x(), (k & 2) ? h.y() : -h.y(), (k & 4) ? h.z() : -h.z()});
  const int q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                       {2, 6, 7, 3}, {1, 3, 7, 5}, {0, 4, 6, 2}};
  for (auto& f : q) {
    m.f.push_back({f[0], f[1], f[2]});
    m.f.push_back({f[0], f[2], f[3]});
  }
  m.round_to_float();
  return m;
}

/// Writes a mesh in all four formats; returns the paths.
std::vector<fs::path> write_all_formats(const TriMesh& m, const fs::path& dir,
                                        const std::string& stem) {
  std::vector<fs::path> paths = {dir / (stem + "_ascii.stl"), dir / (stem + "_binary.stl"),
                                 dir / (stem + ".off"), dir / (stem + ".obj")};
  m.write_ascii_stl(paths[0]);
  m.write_binary_stl(paths[1]);
  m.write_off(paths[2]);
  m.write_obj(paths[3]);
  return paths;
}

class VoxeliseMesh : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("mpm_test_voxelise_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  static fs::path dir_;
};
fs::path VoxeliseMesh::dir_;

const std::string kData = std::string(MPM_TEST_DATA) + "/meshes/";

}  // namespace

// ---------------------------------------------------------------------------------------------
// make_lattice

TEST(MakeLattice, GivenDomainRoundsTheMaximumUpToWholeCells) {
  Scene s = make_scene(3, 0.1, Vec3(0, -0.2, 1.0), Vec3(1.0, 0.33, 1.7));
  const Lattice lat = make_lattice(s);
  EXPECT_EQ(lat.dim, 3);
  EXPECT_DOUBLE_EQ(lat.h, 0.1);
  EXPECT_EQ(lat.origin, Vec3(0, -0.2, 1.0));
  // 1.0/0.1 = 10 exactly; 0.53/0.1 -> 6 (rounded up); 0.7/0.1 = 6.999999999999999 in floating
  // point, which the 1e-9 allowance keeps at 7 (not 7 + a sliver cell).
  EXPECT_EQ(lat.cells, (std::array<int, 3>{10, 6, 7}));
  EXPECT_NEAR(lat.max().y(), 0.4, 1e-12);
  EXPECT_EQ(lat.cell_count(), 420);
}

TEST(MakeLattice, QuotientsJustAboveAnIntegerDoNotAddACell) {
  // 0.9/0.03 = 30.000000000000004, 0.33/0.03 = 11.000000000000002, 0.45/0.03 =
  // 15.000000000000002 in floating point: whole numbers of cells up to rounding, which the
  // 1e-9 allowance keeps whole.
  Scene s = make_scene(3, 0.03, Vec3(0, 0, 0), Vec3(0.9, 0.33, 0.45));
  ASSERT_GT(0.9 / 0.03, 30.0);  // the case this test is about
  EXPECT_EQ(make_lattice(s).cells, (std::array<int, 3>{30, 11, 15}));
  // A real excess, however small against h, is a whole extra cell.
  s.grid.domain_max.x() = 0.9 + 1e-6;
  EXPECT_EQ(make_lattice(s).cells[0], 31);
}

TEST(FitLattice, FittedDomainIsTheBodiesBoxPlusPadding) {
  Scene s = make_scene(3, 0.1, Vec3::Zero(), Vec3::Zero());
  s.grid.domain_given = false;
  s.grid.padding = 0.2;
  s.bodies = {sphere("ball", 0.5, Vec3(1, 2, 3)),
              box("plate", Vec3(0.4, 0.2, 0.1), Vec3(2.0, 2, 3))};
  const Lattice lat = fit_lattice(s);
  // x from 0.5 - 0.2 to 2.2 + 0.2; y from 1.5 - 0.2 to 2.5 + 0.2; z likewise.
  EXPECT_NEAR(lat.origin.x(), 0.3, 1e-12);
  EXPECT_NEAR(lat.origin.y(), 1.3, 1e-12);
  EXPECT_NEAR(lat.origin.z(), 2.3, 1e-12);
  EXPECT_EQ(lat.cells, (std::array<int, 3>{21, 14, 14}));

  // A rotated cylinder: its exact box (end disks) decides the fit. Axis along +x after 90 deg
  // about y: x from 0 to 1, y and z within +-0.25.
  BodySpec c = cylinder("bar", 0.25, 1.0);
  c.rotate_deg = Vec3(0, 90, 0);
  s.bodies = {c};
  s.grid.padding = 0;
  const Lattice lc = fit_lattice(s);
  EXPECT_NEAR(lc.origin.x(), 0.0, 1e-12);
  EXPECT_NEAR(lc.origin.y(), -0.25, 1e-12);
  EXPECT_EQ(lc.cells, (std::array<int, 3>{10, 5, 5}));
}

TEST(FitLattice, TwoDimensionsUseXAndYOnly) {
  Scene s = make_scene(2, 0.05, Vec3::Zero(), Vec3::Zero());
  s.grid.domain_given = false;
  s.grid.padding = 0.1;
  BodySpec d = sphere("disk", 0.5, Vec3(0, 0, 7));  // z is ignored in 2D
  s.bodies = {d};
  const Lattice lat = fit_lattice(s);
  EXPECT_EQ(lat.dim, 2);
  EXPECT_EQ(lat.cells, (std::array<int, 3>{24, 24, 1}));
  EXPECT_NEAR(lat.origin.x(), -0.6, 1e-12);
  EXPECT_EQ(lat.origin.z(), 0.0);
  EXPECT_EQ(lat.cell_count(), 24 * 24);
}

TEST(FitLattice, AGivenDomainIsMakeLattices) {
  Scene s = make_scene(3, 0.1, Vec3(0, -0.2, 1.0), Vec3(1.0, 0.33, 1.7));
  s.bodies = {sphere("ball", 0.5, Vec3(1, 2, 3))};  // outside: the domain is not fitted
  const Lattice a = fit_lattice(s), b = make_lattice(s);
  EXPECT_EQ(a.origin, b.origin);
  EXPECT_EQ(a.cells, b.cells);
}

TEST(MakeLattice, RefusesASceneWithoutDomain) {
  // mpm-run's scenes always have one (mpm-prep writes it); fitting one is mpm-prep's job.
  Scene s = make_scene(3, 0.1, Vec3::Zero(), Vec3::Zero());
  s.grid.domain_given = false;
  s.bodies = {sphere("ball", 0.5, Vec3(1, 2, 3))};
  const std::string msg = input_error_of([&] { make_lattice(s); });
  EXPECT_NE(msg.find("scene.toml:3: grid.domain: the scene gives no domain"), std::string::npos)
      << msg;
}

TEST(MakeLattice, RefusesBadCellSizesAndHugeDomains) {
  Scene s = make_scene(3, 0.0, Vec3::Zero(), Vec3::Ones());
  std::string msg = input_error_of([&] { make_lattice(s); });
  EXPECT_NE(msg.find("scene.toml:3: grid.cell_size"), std::string::npos) << msg;

  s.grid.cell_size = -1;
  EXPECT_THROW(make_lattice(s), InputError);

  s.grid.cell_size = 1e-5;  // 1e5 cells per axis, 1e15 in all > 2^40
  msg = input_error_of([&] { make_lattice(s); });
  EXPECT_NE(msg.find("the domain would need 1000000000000000 cells; enlarge grid.cell_size"),
            std::string::npos)
      << msg;

  Scene s2 = make_scene(2, 1e-10, Vec3::Zero(), Vec3::Ones());  // 1e10 cells along x > 2^31
  msg = input_error_of([&] { make_lattice(s2); });
  EXPECT_NE(msg.find("cells along x"), std::string::npos) << msg;

  Scene s3 = make_scene(3, 0.1, Vec3::Zero(), Vec3(1, 0, 1));  // empty along y
  msg = input_error_of([&] { make_lattice(s3); });
  EXPECT_NE(msg.find("grid.domain"), std::string::npos) << msg;
}

// ---------------------------------------------------------------------------------------------
// Primitives

TEST(Voxelise, AlignedBoxGivesTheExactCountAndColumns) {
  Scene s = make_scene(3, 0.05, Vec3::Zero(), Vec3::Ones());
  // Faces on cell planes: x 0.35..0.65 (6 cells), y 0.4..0.6 (4), z 0.3..0.7 (8).
  BodySpec b = box("block", Vec3(0.3, 0.2, 0.4), Vec3(0.5, 0.5, 0.5));
  b.material = 1;
  b.velocity = Vec3(10, -20, 30);
  s.bodies = {b};
  Voxels r = run(s);
  const std::size_t n = 12 * 8 * 16;
  ASSERT_EQ(r.store.size(), n);

  const double pv = std::pow(0.025, 3);
  const auto* id = r.store.get<std::uint32_t>("id");
  const auto* body = r.store.get<std::uint8_t>("body");
  const auto* mat = r.store.get<std::uint8_t>("material");
  const auto* v = r.store.get<Eigen::Vector3d>("v");
  const auto* m = r.store.get<double>("m");
  const auto* rho = r.store.get<double>("rho");
  ASSERT_TRUE(id && body && mat && v && m && rho);
  EXPECT_EQ(r.store.at("x").info().components, 3);
  EXPECT_EQ(r.store.at("x").info().type, ScalarType::F64);
  for (std::size_t p = 0; p < n; ++p) {
    ASSERT_EQ(id[p], p);
    ASSERT_EQ(body[p], 0);
    ASSERT_EQ(mat[p], 1);
    ASSERT_EQ(v[p], Vec3(10, -20, 30));
    ASSERT_DOUBLE_EQ(m[p], 2700 * pv);
    ASSERT_EQ(rho[p], 2700);
  }
  // First particle: cell (7, 8, 6) corner + h/4.
  EXPECT_NEAR((position(r, 0) - Vec3(0.3625, 0.4125, 0.3125)).norm(), 0, 1e-12);

  ASSERT_EQ(r.report.size(), 1u);
  EXPECT_EQ(r.report[0].name, "block");
  EXPECT_EQ(r.report[0].particles, n);
  EXPECT_DOUBLE_EQ(r.report[0].spacing, 0.025);
  EXPECT_NEAR(r.report[0].mass, 2700 * 0.3 * 0.2 * 0.4, 1e-9);
  EXPECT_NEAR(r.report[0].exact_mass, 2700 * 0.3 * 0.2 * 0.4, 1e-9);
  EXPECT_EQ(r.report[0].skipped_overlap, 0u);
}

TEST(Voxelise, OutputIsInLatticeOrder) {
  Scene s = make_scene(3, 0.1, Vec3::Zero(), Vec3::Ones());
  BodySpec c = cylinder("bar", 0.3, 0.6);
  c.translate = Vec3(0.5, 0.5, 0.2);
  c.rotate_deg = Vec3(20, 0, 0);
  c.particles_per_cell = 3;
  s.bodies = {c};
  Voxels r = run(s);
  ASSERT_GT(r.store.size(), 1000u);
  // Key: cell z, y, x, then point z, y, x within the cell.
  auto key = [&](std::size_t p) {
    const auto ijk = point_index(r, p, 3);
    std::array<long long, 6> k{};
    for (int a = 0; a < 3; ++a) {
      k[2 - a] = ijk[a] / 3;  // cell index
      k[5 - a] = ijk[a] % 3;  // point within the cell
    }
    return k;
  };
  for (std::size_t p = 1; p < r.store.size(); ++p)
    ASSERT_LT(key(p - 1), key(p)) << "particle " << p;
}

TEST(Voxelise, SphereAndCylinderVolumesWithinOnePercent) {
  // 20 cells across the diameter, 2 particles per cell: count x particle volume vs exact volume.
  // At 40 points across, the lattice error of a smooth convex body is a few tenths of a percent.
  Scene s = make_scene(3, 0.05, Vec3(-0.6, -0.6, -0.6), Vec3(0.6, 0.6, 0.6));
  s.bodies = {sphere("ball", 0.5, Vec3(0.013, -0.021, 0.007))};
  Voxels r = run(s);
  const double v_sphere = 4.0 / 3.0 * kPi * 0.125;
  EXPECT_NEAR(r.store.size() * particle_volume(r) / v_sphere, 1.0, 0.01);
  EXPECT_NEAR(r.report[0].exact_mass, 7850 * v_sphere, 1e-9);
  EXPECT_NEAR(r.report[0].mass / r.report[0].exact_mass, 1.0, 0.01);

  // Cylinder along z.
  Scene c = make_scene(3, 0.025, Vec3(-0.3, -0.3, -0.1), Vec3(0.3, 0.3, 0.8));
  BodySpec bar = cylinder("bar", 0.25, 0.6);
  bar.translate = Vec3(0.004, -0.003, 0.011);
  c.bodies = {bar};
  r = run(c);
  const double v_cyl = kPi * 0.25 * 0.25 * 0.6;
  EXPECT_NEAR(r.store.size() * particle_volume(r) / v_cyl, 1.0, 0.01);
}

TEST(Voxelise, RotatedTranslatedCylinderAndScaledSphere) {
  Scene s = make_scene(3, 0.025, Vec3(-1, -1, -1), Vec3(1, 1, 1));
  BodySpec bar = cylinder("bar", 0.25, 0.8);
  bar.rotate_deg = Vec3(30, 45, 60);
  bar.translate = Vec3(0.1, -0.2, -0.3);
  s.bodies = {bar};
  Voxels r = run(s);
  const double v_cyl = kPi * 0.25 * 0.25 * 0.8;
  EXPECT_NEAR(r.store.size() * particle_volume(r) / v_cyl, 1.0, 0.01);
  // Every particle is inside the cylinder mapped back by hand, and inside the region's box.
  auto region = make_region(bar, s);
  EXPECT_NEAR(region->volume(), v_cyl, 1e-12);
  Vec3 lo, hi;
  region->bounds(lo, hi);
  Vec3 plo = Vec3::Constant(1e9), phi = -plo;
  for (std::size_t p = 0; p < r.store.size(); ++p) {
    const Vec3 x = position(r, p);
    const Vec3 u = to_local(bar, x);
    ASSERT_LE(u.head<2>().norm(), 0.25 + 1e-12);
    ASSERT_GE(u.z(), -1e-12);
    ASSERT_LE(u.z(), 0.8 + 1e-12);
    plo = plo.cwiseMin(x);
    phi = phi.cwiseMax(x);
  }
  // The box is tight: particles reach within one particle spacing (plus the sampling gap) of it.
  EXPECT_TRUE((plo.array() >= lo.array()).all() && (phi.array() <= hi.array()).all());
  EXPECT_LT((plo - lo).maxCoeff(), 2 * 0.0125);
  EXPECT_LT((hi - phi).maxCoeff(), 2 * 0.0125);

  // Ellipsoid: sphere of radius 0.5 scaled by (1, 0.6, 1.4), rotated; 20 cells across its
  // smallest diameter (0.6 m).
  Scene e = make_scene(3, 0.03, Vec3(-0.8, -0.8, -0.8), Vec3(0.8, 0.8, 0.8));
  BodySpec egg = sphere("egg", 0.5, Vec3(0.01, 0.02, -0.03));
  egg.scale = Vec3(1, 0.6, 1.4);
  egg.rotate_deg = Vec3(10, -25, 40);
  e.bodies = {egg};
  r = run(e);
  const double v_egg = 4.0 / 3.0 * kPi * 0.125 * 0.6 * 1.4;
  EXPECT_NEAR(make_region(egg, e)->volume(), v_egg, 1e-12);
  EXPECT_NEAR(r.store.size() * particle_volume(r) / v_egg, 1.0, 0.01);
  for (std::size_t p = 0; p < r.store.size(); ++p)
    ASSERT_LE(to_local(egg, position(r, p)).norm(), 0.5 + 1e-12);
}

TEST(Voxelise, OverlappingBodiesSkipSharedPointsAndMassesAddUp) {
  Scene s = make_scene(3, 0.04, Vec3(-0.5, -0.4, -0.4), Vec3(0.5, 0.4, 0.4));
  BodySpec a = sphere("a", 0.3, Vec3(-0.1, 0, 0));
  BodySpec b = sphere("b", 0.3, Vec3(0.15, 0.01, 0));
  b.material = 1;
  s.bodies = {a};
  const Voxels ra = run(s);
  s.bodies = {b};
  const Voxels rb = run(s);
  s.bodies = {a, b};
  const Voxels r = run(s);

  const std::size_t na = ra.store.size(), nb = rb.store.size();
  ASSERT_EQ(r.report.size(), 2u);
  EXPECT_EQ(r.report[0].particles, na);  // the first body is untouched
  EXPECT_EQ(r.report[0].skipped_overlap, 0u);
  EXPECT_GT(r.report[1].skipped_overlap, 100u);  // the lens is a few thousand points
  EXPECT_EQ(r.report[1].particles + r.report[1].skipped_overlap, nb);
  EXPECT_EQ(r.store.size(), na + r.report[1].particles);

  // No point twice; the union is exactly a's points plus b's.
  const auto all = point_set(r, 0, r.store.size());
  EXPECT_EQ(all.size(), r.store.size());
  auto expect = point_set(ra, 0, na);
  const auto pb = point_set(rb, 0, nb);
  expect.insert(pb.begin(), pb.end());
  EXPECT_EQ(all, expect);
  // Points of b kept are outside a.
  for (std::size_t p = na; p < r.store.size(); ++p)
    ASSERT_GT((position(r, p) - a.translate).norm(), 0.3);

  // Masses: columns sum to the reports; the report is count x density x particle volume.
  const auto* m = r.store.get<double>("m");
  const auto* body = r.store.get<std::uint8_t>("body");
  const auto* mat = r.store.get<std::uint8_t>("material");
  double sum[2] = {0, 0};
  for (std::size_t p = 0; p < r.store.size(); ++p) {
    ASSERT_EQ(body[p], p < na ? 0 : 1);
    ASSERT_EQ(mat[p], p < na ? 0 : 1);
    sum[body[p]] += m[p];
  }
  const double pv = std::pow(0.02, 3);
  EXPECT_NEAR(sum[0], r.report[0].mass, 1e-12 * sum[0]);
  EXPECT_NEAR(sum[1], r.report[1].mass, 1e-12 * sum[1]);
  EXPECT_NEAR(r.report[0].mass, 7850 * pv * na, 1e-9);
  EXPECT_NEAR(r.report[1].mass, 2700 * pv * r.report[1].particles, 1e-9);
}

TEST(Voxelise, TwoDimensionalRectangleAndDisk) {
  Scene s = make_scene(2, 0.05, Vec3(0, 0, 0), Vec3(1, 1, 0));
  BodySpec rect = box("plate", Vec3(0.3, 0.2, 0), Vec3(0.5, 0.5, 0));  // faces on cell lines
  rect.particles_per_cell = 3;
  s.bodies = {rect};
  Voxels r = run(s);
  EXPECT_EQ(r.store.size(), std::size_t(6 * 3 * 4 * 3));
  EXPECT_EQ(r.store.at("x").info().components, 2);
  EXPECT_EQ(r.store.at("v").info().components, 2);
  const double sp = 0.05 / 3;
  // Mass per metre of thickness: density x (h/n)^2 x 1 m.
  EXPECT_DOUBLE_EQ(r.store.get<double>("m")[0], 7850 * sp * sp);
  EXPECT_NEAR(r.report[0].exact_mass, 7850 * 0.3 * 0.2, 1e-9);

  // Disk, 20 cells across, rotated and scaled into an ellipse of semi-axes 0.5 x 0.35.
  Scene d = make_scene(2, 0.05, Vec3(-0.6, -0.6, 0), Vec3(0.6, 0.6, 0));
  d.bodies = {sphere("disk", 0.5, Vec3(0.012, -0.007, 0))};
  r = run(d);
  EXPECT_NEAR(r.store.size() * particle_volume(r) / (kPi * 0.25), 1.0, 0.01);
  BodySpec ell = sphere("ellipse", 0.5, Vec3(0.012, -0.007, 0));
  ell.scale = Vec3(1, 0.7, 5);  // z scale is ignored in 2D
  ell.rotate_deg = Vec3(0, 0, 30);
  d.grid.cell_size = 0.035;  // 20 cells across the short axis
  d.bodies = {ell};
  r = run(d);
  const double area = kPi * 0.5 * 0.35;
  EXPECT_NEAR(make_region(ell, d)->volume(), area, 1e-12);
  EXPECT_NEAR(r.store.size() * particle_volume(r) / area, 1.0, 0.01);
  const Mat3 rz = rotation(Vec3(0, 0, 30));
  for (std::size_t p = 0; p < r.store.size(); ++p) {
    const Vec3 u = rz.transpose() * (position(r, p) - ell.translate);
    ASSERT_LE(std::hypot(u.x() / 1.0, u.y() / 0.7), 0.5 + 1e-12);
  }

  // 2D refuses cylinders, meshes and out-of-plane rotations.
  d.bodies = {cylinder("bar", 0.1, 0.5)};
  EXPECT_NE(input_error_of([&] { run(d); }).find("bodies.bar.shape"), std::string::npos);
  d.bodies = {mesh_body("m", kData + "box_12.stl")};
  EXPECT_NE(input_error_of([&] { run(d); }).find("bodies.m.shape"), std::string::npos);
  BodySpec tilted = sphere("t", 0.2, Vec3::Zero());
  tilted.rotate_deg = Vec3(10, 0, 0);
  d.bodies = {tilted};
  EXPECT_NE(input_error_of([&] { run(d); }).find("bodies.t.rotate:"), std::string::npos);
}

// particle_spacing: a lattice of the body's own, independent of the cells (the seed's large V4
// model: 0.21 mm spacing in 1 mm cells, 4.76 particles per cell along each axis).
TEST(Voxelise, ParticleSpacingTilesABoxIndependentlyOfTheCells) {
  Scene s = make_scene(3, 0.1, Vec3::Zero(), Vec3::Ones());
  // 0.3 x 0.15 x 0.09 at spacing 0.03: 10 x 5 x 3 points, 3.33 per cell along each axis, the
  // box off the cell planes.
  BodySpec b = box("block", Vec3(0.3, 0.15, 0.09), Vec3(0.513, 0.47, 0.555));
  b.particle_spacing = 0.03;
  s.bodies = {b};
  Voxels r = run(s);
  ASSERT_EQ(r.store.size(), 150u);
  const double pv = 0.03 * 0.03 * 0.03;
  const auto* m = r.store.get<double>("m");
  for (std::size_t p = 0; p < r.store.size(); ++p) ASSERT_DOUBLE_EQ(m[p], 7850 * pv);
  // The particles tile the box exactly: their mass is the box's.
  EXPECT_NEAR(r.report[0].mass / r.report[0].exact_mass, 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(r.report[0].spacing, 0.03);
  // Along each axis: the lattice centred on the box, spacing 0.03, half a spacing in from the
  // faces.
  const Vec3 lo = b.translate - 0.5 * b.size;
  std::array<std::set<long long>, 3> seen;
  for (std::size_t p = 0; p < r.store.size(); ++p) {
    const Vec3 x = position(r, p);
    for (int a = 0; a < 3; ++a) {
      const double i = (x[a] - lo[a]) / 0.03 - 0.5;
      ASSERT_NEAR(i, std::round(i), 1e-9) << "particle " << p << " axis " << a;
      seen[a].insert(std::llround(i));
    }
  }
  EXPECT_EQ(seen[0].size(), 10u);
  EXPECT_EQ(seen[1].size(), 5u);
  EXPECT_EQ(seen[2].size(), 3u);
  // Cell order (cell z, y, x slowest to fastest), as for particles_per_cell: cells hold 3 or 4
  // points along an axis here.
  auto cell_key = [&](std::size_t p) {
    const Vec3 x = position(r, p);
    std::array<long long, 3> c{};
    for (int a = 0; a < 3; ++a) c[2 - a] = static_cast<long long>(std::floor(x[a] / 0.1));
    return c;
  };
  for (std::size_t p = 1; p < r.store.size(); ++p) ASSERT_LE(cell_key(p - 1), cell_key(p)) << p;
}

TEST(Voxelise, ParticleSpacingOfACellFractionIsParticlesPerCell) {
  // A box on the cell planes at spacing h / 2 gives exactly the particles of
  // particles_per_cell = 2, in the same order.
  Scene s = make_scene(3, 0.05, Vec3::Zero(), Vec3::Ones());
  BodySpec b = box("block", Vec3(0.3, 0.2, 0.4), Vec3(0.5, 0.5, 0.5));
  s.bodies = {b};
  Voxels by_n = run(s);
  s.bodies[0].particle_spacing = 0.025;
  Voxels by_s = run(s);
  ASSERT_EQ(by_s.store.size(), by_n.store.size());
  const auto* ma = by_n.store.get<double>("m");
  const auto* mb = by_s.store.get<double>("m");
  for (std::size_t p = 0; p < by_n.store.size(); ++p) {
    ASSERT_NEAR((position(by_s, p) - position(by_n, p)).norm(), 0, 1e-12) << p;
    ASSERT_DOUBLE_EQ(mb[p], ma[p]);
  }
}

TEST(Voxelise, ParticleSpacingLatticeIsSymmetricAboutASphere) {
  // 0.037 in cells of 0.1 (2.7 per cell): the lattice is centred on the sphere, so the
  // particles' centre of mass is the sphere's centre and the count along each axis is odd.
  Scene s = make_scene(3, 0.1, Vec3(-1, -1, -1), Vec3(1, 1, 1));
  const Vec3 c(0.0123, -0.2345, 0.3456);
  BodySpec ball = sphere("ball", 0.4, c);
  ball.particle_spacing = 0.037;
  s.bodies = {ball};
  Voxels r = run(s);
  Vec3 sum = Vec3::Zero();
  for (std::size_t p = 0; p < r.store.size(); ++p) sum += position(r, p);
  EXPECT_NEAR((sum / double(r.store.size()) - c).norm(), 0, 1e-12);
  // round(0.8 / 0.037) = 22 points per axis: about 21.6^3 pi / 6 of them inside.
  const double v = 4.0 / 3.0 * kPi * 0.064;
  EXPECT_NEAR(r.store.size() * std::pow(0.037, 3) / v, 1.0, 0.03);
  EXPECT_NEAR(r.report[0].mass / r.report[0].exact_mass, 1.0, 0.03);
}

TEST(Voxelise, ParticleSpacingInTwoDimensionsAndAxisymmetric) {
  // A 2D rectangle at spacing 0.04 in cells of 0.1, plane and axisymmetric (mass per radian
  // A r: Pappus's theorem gives the exact ring mass when the lattice tiles the rectangle).
  for (bool axi : {false, true}) {
    Scene s = make_scene(2, 0.1, Vec3(0, 0, 0), Vec3(1, 1, 0));
    s.axisymmetric = axi;
    BodySpec b = box("ring", Vec3(0.2, 0.32, 0), Vec3(0.5, 0.41, 0));
    b.particle_spacing = 0.04;
    s.bodies = {b};
    Voxels r = run(s);
    ASSERT_EQ(r.store.size(), 5u * 8u) << axi;
    EXPECT_NEAR(r.report[0].mass / r.report[0].exact_mass, 1.0, 1e-12) << axi;
  }
}

// Axisymmetric exact masses (per radian: the integral of r over the part at r >= 0) for bodies
// that cross the axis, are rotated or scaled, against closed forms; the particles' masses
// converge to them.
TEST(Voxelise, AxisymmetricExactMassOfBodiesCrossingTheAxis) {
  const double rho = 7850;
  Scene s = make_scene(2, 0.01, Vec3(0, -0.5, 0), Vec3(1, 0.5, 0));
  s.axisymmetric = true;
  auto exact = [&](const BodySpec& b) {
    s.bodies = {b};
    return run(s).report[0];
  };
  // A disk centred on the axis is a sphere: 4/3 pi R^3 / (2 pi) = 2/3 R^3 per radian.
  BodyReport r = exact(sphere("ball", 0.2, Vec3(0, 0, 0)));
  EXPECT_NEAR(r.exact_mass, rho * 2.0 / 3.0 * 0.008, 1e-12);
  EXPECT_NEAR(r.mass / r.exact_mass, 1.0, 0.01);
  // Off the axis: Pappus, area times the centre's radius (a torus).
  r = exact(sphere("torus", 0.1, Vec3(0.3, 0, 0)));
  EXPECT_NEAR(r.exact_mass, rho * kPi * 0.01 * 0.3, 1e-12);
  // Crossing the axis at a quarter of the radius: R = 0.2, centre at x = 0.05. With
  // u = x - 0.05 from -0.05 to R: 0.05 (R^2 (pi/2 + asin(1/4)) + 0.05 sqrt(R^2 - 0.0025))
  // + 2/3 (R^2 - 0.0025)^(3/2), the integral of (0.05 + u) 2 sqrt(R^2 - u^2).
  r = exact(sphere("cut", 0.2, Vec3(0.05, 0, 0)));
  const double q = 0.04 - 0.0025;
  EXPECT_NEAR(r.exact_mass,
              rho * (0.05 * (0.04 * (kPi / 2 + std::asin(0.25)) + 0.05 * std::sqrt(q)) +
                     2.0 / 3.0 * std::pow(q, 1.5)),
              1e-12);
  EXPECT_NEAR(r.mass / r.exact_mass, 1.0, 0.01);
  // An ellipse (the disk scaled by 2 along x) centred on the axis: an oblate spheroid, 4/3 pi
  // a^2 b / (2 pi) with a = 0.4, b = 0.2.
  BodySpec e = sphere("spheroid", 0.2, Vec3(0, 0, 0));
  e.scale = Vec3(2, 1, 1);
  r = exact(e);
  EXPECT_NEAR(r.exact_mass, rho * 2.0 / 3.0 * 0.16 * 0.2, 1e-12);
  EXPECT_NEAR(r.mass / r.exact_mass, 1.0, 0.01);
  // A box from x = -0.2 to 0.6, 0.3 high: the integral of x over 0 .. 0.6, times 0.3.
  r = exact(box("slab", Vec3(0.8, 0.3, 0), Vec3(0.2, 0, 0)));
  EXPECT_NEAR(r.exact_mass, rho * 0.18 * 0.3, 1e-12);
  EXPECT_NEAR(r.mass / r.exact_mass, 1.0, 1e-12);  // the lattice tiles the part at x >= 0
  // A square of side 0.2 rotated by 45 degrees about its centre on the axis: the half at x >= 0
  // is a triangle of apex 0.1 sqrt(2), area 0.02, its centroid at 0.1 sqrt(2) / 3.
  BodySpec d = box("diamond", Vec3(0.2, 0.2, 0), Vec3(0, 0, 0));
  d.rotate_deg = Vec3(0, 0, 45);
  r = exact(d);
  EXPECT_NEAR(r.exact_mass, rho * 0.02 * 0.1 * std::sqrt(2.0) / 3.0, 1e-12);
  EXPECT_NEAR(r.mass / r.exact_mass, 1.0, 0.03);  // staircase edges: spacing 0.005 / apex 0.14
  // Rotated and wholly off the axis: Pappus again.
  d.translate = Vec3(0.5, 0, 0);
  r = exact(d);
  EXPECT_NEAR(r.exact_mass, rho * 0.04 * 0.5, 1e-12);
}

TEST(Voxelise, BodyOutsideTheDomainOrTooThinIsRefused) {
  Scene s = make_scene(3, 0.1, Vec3::Zero(), Vec3::Ones());
  BodySpec far = sphere("far", 0.2, Vec3(5, 5, 5));
  far.loc.line = 42;
  s.bodies = {sphere("ok", 0.3, Vec3(0.5, 0.5, 0.5)), far};
  std::string msg = input_error_of([&] { run(s); });
  EXPECT_NE(msg.find("scene.toml:42: bodies.far"), std::string::npos) << msg;
  EXPECT_NE(msg.find("body 'far' has no particles"), std::string::npos) << msg;
  EXPECT_NE(msg.find("particle spacing (0.05 m)"), std::string::npos) << msg;

  // A sheet thinner than the particle spacing that falls between two point planes.
  s.bodies = {box("foil", Vec3(0.5, 0.5, 0.01), Vec3(0.5, 0.5, 0.5))};
  msg = input_error_of([&] { run(s); });
  EXPECT_NE(msg.find("body 'foil' has no particles"), std::string::npos) << msg;

  // A body wholly inside an earlier one.
  s.bodies = {sphere("big", 0.4, Vec3(0.5, 0.5, 0.5)), sphere("pip", 0.1, Vec3(0.5, 0.5, 0.5))};
  msg = input_error_of([&] { run(s); });
  EXPECT_NE(msg.find("body 'pip' has no particles: all its"), std::string::npos) << msg;

  // Bad material index.
  BodySpec nomat = sphere("nomat", 0.2, Vec3(0.5, 0.5, 0.5));
  nomat.material = 7;
  s.bodies = {nomat};
  msg = input_error_of([&] { run(s); });
  EXPECT_NE(msg.find("bodies.nomat.material"), std::string::npos) << msg;
}

TEST(Voxelise, RefusesBadShapesAndOverlappingBodies) {
  Scene s = make_scene(3, 0.1, Vec3::Zero(), Vec3::Ones());
  s.bodies = {box("flat", Vec3(0.2, 0, 0.2), Vec3(0.5, 0.5, 0.5))};
  EXPECT_NE(input_error_of([&] { run(s); }).find("scene.toml:10: bodies.flat.size"),
            std::string::npos);
  s.bodies = {sphere("dot", 0, Vec3(0.5, 0.5, 0.5))};
  EXPECT_NE(input_error_of([&] { run(s); }).find("bodies.dot.radius"), std::string::npos);
  BodySpec c = cylinder("stub", 0.1, -1);
  c.translate = Vec3(0.5, 0.5, 0.5);
  s.bodies = {c};
  EXPECT_NE(input_error_of([&] { run(s); }).find("bodies.stub.length"), std::string::npos);
  BodySpec z = sphere("squashed", 0.2, Vec3(0.5, 0.5, 0.5));
  z.scale = Vec3(1, 0, 1);
  s.bodies = {z};
  EXPECT_NE(input_error_of([&] { run(s); }).find("bodies.squashed.scale"), std::string::npos);
  BodySpec q = sphere("coarse", 0.2, Vec3(0.5, 0.5, 0.5));
  q.particles_per_cell = 0;
  s.bodies = {q};
  EXPECT_NE(input_error_of([&] { run(s); }).find("bodies.coarse.particles_per_cell"),
            std::string::npos);

  // No limit of 255 bodies any more (ids are 32-bit past 255, tests/cli/test_many_bodies.cpp):
  // 256 spheres in one place are refused for their overlap, not their number.
  s.bodies.clear();
  for (int i = 0; i < 256; ++i) {
    char name[16];  // (not "b" + std::to_string(i): GCC 12 warns falsely with -Wrestrict)
    std::snprintf(name, sizeof name, "b%d", i);
    s.bodies.push_back(sphere(name, 0.2, Vec3::Ones() * 0.5));
  }
  const std::string msg = input_error_of([&] { run(s); });
  EXPECT_EQ(msg.find("at most 255"), std::string::npos) << msg;
  EXPECT_NE(msg.find("body 'b1' has no particles: all its"), std::string::npos) << msg;
}

TEST(Voxelise, OutputDoesNotDependOnTheThreadCount) {
  Scene s = make_scene(3, 0.04, Vec3(-0.5, -0.5, -0.5), Vec3(0.5, 0.5, 0.5));
  BodySpec c = cylinder("bar", 0.2, 0.6);
  c.rotate_deg = Vec3(15, 30, 0);
  c.translate = Vec3(0.01, 0.02, -0.3);
  BodySpec m = mesh_body("cube", kData + "box_12.stl");
  m.scale = Vec3(0.5, 0.4, 0.3);
  m.rotate_deg = Vec3(0, 0, 20);
  s.bodies = {c, sphere("ball", 0.25, Vec3(0.1, -0.1, 0.05)), m};
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  const Voxels one = run(s);
  ASSERT_GT(one.store.size(), 1000u);
  EXPECT_GT(one.report[1].skipped_overlap, 0u);
  for (int threads : {2, 4}) {  // 4 oversubscribes 2 cores: more interleavings
    SCOPED_TRACE(threads);
    omp_set_num_threads(threads);
    const Voxels many = run(s);
    expect_identical(one.store, many.store);
    for (int b = 0; b < 3; ++b) {
      EXPECT_EQ(one.report[b].particles, many.report[b].particles);
      EXPECT_EQ(one.report[b].skipped_overlap, many.report[b].skipped_overlap);
    }
  }
  omp_set_num_threads(saved);
}

// ---------------------------------------------------------------------------------------------
// Meshes

TEST_F(VoxeliseMesh, IcosphereMeshesInEveryFormatMatchTheSphere) {
  const double radius = 0.5;
  const TriMesh ico = icosphere(radius, 5);  // 20480 triangles
  const double v_sphere = 4.0 / 3.0 * kPi * radius * radius * radius;
  ASSERT_NEAR(ico.volume() / v_sphere, 1.0, 1e-3);  // faceting loses 0.054%
  const auto paths = write_all_formats(ico, dir_, "ico");

  Scene s = make_scene(3, 0.05, Vec3(-0.6, -0.6, -0.6), Vec3(0.6, 0.6, 0.6));
  const Vec3 centre(0.013, -0.021, 0.007);
  s.bodies = {sphere("ball", radius, centre)};
  const Voxels prim = run(s);
  const auto prim_set = point_set(prim, 0, prim.store.size());
  // Points between the facets and the sphere: inside the sphere, outside the insphere of the
  // polyhedron (radius = nearest face plane). The mesh may lose exactly these, nothing else.
  const double r_in = ico.min_plane_distance();
  std::size_t shell = 0;
  for (std::size_t p = 0; p < prim.store.size(); ++p)
    if ((position(prim, p) - centre).norm() > r_in) ++shell;

  std::vector<Voxels> runs;
  for (const auto& path : paths) {
    SCOPED_TRACE(path.string());
    BodySpec b = mesh_body("ball", path.string());
    b.translate = centre;
    s.bodies = {b};
    runs.push_back(run(s));
    const Voxels& r = runs.back();
    EXPECT_NEAR(make_region(b, s)->volume(), ico.volume(), 1e-9 * ico.volume());
    const auto mesh_set = point_set(r, 0, r.store.size());
    // The polyhedron is inscribed in the sphere: its points are a subset of the sphere's.
    EXPECT_TRUE(std::includes(prim_set.begin(), prim_set.end(), mesh_set.begin(), mesh_set.end()));
    const std::size_t lost = prim.store.size() - r.store.size();
    EXPECT_LE(lost, shell);
    // The points it loses are in the thin shell between insphere and sphere.
    for (std::size_t p = 0; p < prim.store.size(); ++p) {
      if (mesh_set.count(point_index(prim, p))) continue;
      ASSERT_GT((position(prim, p) - centre).norm(), r_in - 1e-12);
    }
    // And the count difference is the faceting loss: 0.054% of 33 500 points, ~18, a few more
    // or less by how the lattice samples a thin shell.
    const double expected_lost = (v_sphere - ico.volume()) / particle_volume(prim);
    EXPECT_NEAR(double(lost), expected_lost, 3 * std::sqrt(expected_lost) + 5);
  }
  // Every format stores the same (float) vertices, so the particles are identical.
  for (std::size_t i = 1; i < runs.size(); ++i) expect_identical(runs[0].store, runs[i].store);
}

TEST_F(VoxeliseMesh, CylinderMeshMatchesTheRotatedCylinder) {
  const double radius = 0.25, length = 0.8;
  const int segments = 128;
  const TriMesh cyl = cylinder_mesh(radius, length, segments);
  const double v_cyl = kPi * radius * radius * length;
  ASSERT_NEAR(cyl.volume() / v_cyl, 1.0, 1e-3);  // 1 - sin(2pi/N)/(2pi/N) = 0.04%
  const auto paths = write_all_formats(cyl, dir_, "cyl");

  Scene s = make_scene(3, 0.025, Vec3(-1, -1, -1), Vec3(1, 1, 1));
  BodySpec bar = cylinder("bar", radius, length);
  bar.rotate_deg = Vec3(30, 45, 60);
  bar.translate = Vec3(0.1, -0.2, -0.3);
  s.bodies = {bar};
  const Voxels prim = run(s);
  const double apothem = radius * std::cos(kPi / segments);
  for (const auto& path : {paths[0], paths[1]}) {  // ASCII and binary STL
    SCOPED_TRACE(path.string());
    BodySpec b = mesh_body("bar", path.string());
    b.rotate_deg = bar.rotate_deg;
    b.translate = bar.translate;
    s.bodies = {b};
    const Voxels r = run(s);
    const auto mesh_set = point_set(r, 0, r.store.size());
    const auto prim_set = point_set(prim, 0, prim.store.size());
    EXPECT_TRUE(std::includes(prim_set.begin(), prim_set.end(), mesh_set.begin(), mesh_set.end()));
    for (std::size_t p = 0; p < prim.store.size(); ++p) {
      if (mesh_set.count(point_index(prim, p))) continue;
      ASSERT_GT(to_local(bar, position(prim, p)).head<2>().norm(), apothem - 1e-9);
    }
    const double expected_lost = (v_cyl - cyl.volume()) / particle_volume(prim);
    const double lost = double(prim.store.size() - r.store.size());
    EXPECT_NEAR(lost, expected_lost, 3 * std::sqrt(expected_lost) + 5);
  }
}

TEST_F(VoxeliseMesh, BoxMeshGivesExactlyTheBoxPrimitiveParticles) {
  // Generic size, rotation and position: no lattice point lies on the surface.
  const Vec3 size(0.37, 0.23, 0.51);
  const auto paths = write_all_formats(box_mesh(Vec3::Ones()), dir_, "unitbox");
  Scene s = make_scene(3, 0.04, Vec3(-0.5, -0.5, -0.5), Vec3(0.5, 0.5, 0.5));
  BodySpec prim = box("brick", size, Vec3(0.031, -0.017, 0.023));
  prim.rotate_deg = Vec3(17, -33, 52);
  s.bodies = {prim};
  const Voxels rp = run(s);
  ASSERT_GT(rp.store.size(), 1000u);
  // Unit cube mesh scaled to the size: same body as the primitive, in every format. Also the
  // checked-in 12-triangle STL and the quad-faced OBJ (v/vt/vn faces, triangulated on reading).
  // A binary STL whose header starts with "solid " (read as ASCII first, then as binary).
  const fs::path solid_binary = dir_ / "unitbox_solid_header.stl";
  box_mesh(Vec3::Ones()).write_binary_stl(solid_binary, "solid exported by a CAD tool");
  std::vector<std::string> files = {
      paths[0].string(),     paths[1].string(),    paths[2].string(),       paths[3].string(),
      solid_binary.string(), kData + "box_12.stl", kData + "cube_quads.obj"};
  for (const auto& f : files) {
    SCOPED_TRACE(f);
    BodySpec m = mesh_body("brick", f);
    m.scale = size;
    m.rotate_deg = prim.rotate_deg;
    m.translate = prim.translate;
    s.bodies = {m};
    const Voxels rm = run(s);
    EXPECT_NEAR(make_region(m, s)->volume(), size.prod(), 1e-12);
    expect_identical(rp.store, rm.store);
  }

  // With a spacing of its own, 0.017 in cells of 0.04 (2 or 3 points per cell along an axis):
  // the mesh path (cells wholly inside taken without a test, the others point by point) gives
  // the primitive's particles, on the lattice centred on the same bounding box.
  prim.particle_spacing = 0.017;
  s.bodies = {prim};
  const Voxels sp = run(s);
  EXPECT_NEAR(sp.store.size() * std::pow(0.017, 3) / size.prod(), 1.0, 0.03);
  BodySpec m = mesh_body("brick", paths[0].string());
  m.scale = size;
  m.rotate_deg = prim.rotate_deg;
  m.translate = prim.translate;
  m.particle_spacing = 0.017;
  s.bodies = {m};
  const Voxels sm = run(s);
  ASSERT_EQ(sm.store.size(), sp.store.size());
  for (std::size_t p = 0; p < sp.store.size(); ++p)
    ASSERT_NEAR((position(sm, p) - position(sp, p)).norm(), 0, 1e-12) << p;
}

// Shared vertices a hair apart (issue 26: an STL with vertices 1e-18 m apart was "not closed"):
// the unit cube [0, 1]^3 where one face uses a copy of the corner (0, 0, 0) moved by 1e-18 m.
// Vertices within 1e-7 of the mesh's diagonal are one vertex, so the cube is closed and has its
// volume (exact for a cube: 1e-12 is round-off).
TEST_F(VoxeliseMesh, VerticesAHairApartAreWelded) {
  const fs::path path = dir_ / "hair.off";
  {
    FILE* out = std::fopen(path.c_str(), "w");
    ASSERT_TRUE(out);
    std::fprintf(out, "OFF\n9 12 0\n");
    for (int k = 0; k < 8; ++k) std::fprintf(out, "%d %d %d\n", k & 1, (k >> 1) & 1, k >> 2);
    std::fprintf(out, "%.17g 0 0\n", 1e-18);
    const int f[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                          {2, 6, 7}, {2, 7, 3}, {8, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
    for (const auto& t : f) std::fprintf(out, "3 %d %d %d\n", t[0], t[1], t[2]);
    std::fclose(out);
  }
  Scene s = make_scene(3, 0.1, Vec3(-1, -1, -1), Vec3(2, 2, 2));
  s.bodies = {mesh_body("cube", path.string())};
  EXPECT_NEAR(make_region(s.bodies[0], s)->volume(), 1.0, 1e-12);
  const Voxels r = run(s);
  EXPECT_EQ(r.store.size(), std::size_t(20 * 20 * 20));  // 10 cells, 2 points each, per axis
}

TEST_F(VoxeliseMesh, MeshRelativeToTheSceneDirectory) {
  Scene s = make_scene(3, 0.1, Vec3(-1, -1, -1), Vec3(1, 1, 1));
  s.directory = std::string(MPM_TEST_DATA) + "/meshes";
  s.bodies = {mesh_body("cube", "box_12.stl")};
  const Voxels r = run(s);
  // Unit cube with faces on cell planes: 10 cells, 20 points per axis.
  EXPECT_EQ(r.store.size(), std::size_t(20 * 20 * 20));
}

TEST_F(VoxeliseMesh, BadMeshesAreRefusedNamingTheFile) {
  Scene s = make_scene(3, 0.1, Vec3(-1, -1, -1), Vec3(1, 1, 1));
  s.bodies = {mesh_body("lid", kData + "open_cube.stl", 17)};
  std::string msg = input_error_of([&] { run(s); });
  EXPECT_NE(msg.find("scene.toml:17: bodies.lid.file"), std::string::npos) << msg;
  // The hole is named by where it is: the cube's missing face at z = -0.5.
  EXPECT_NE(msg.find("open_cube.stl' is not closed: 4 border edges around 1 hole: 4 edges around "
                     "(0, 0, -0.5) in the file's coordinates; close it or use a primitive"),
            std::string::npos)
      << msg;

  // A box without its two z faces, placed at 1/1000 of its size elsewhere: two holes, each
  // named in the file's own coordinates (placement undone), where a user would look for it.
  TriMesh tube = box_mesh(Vec3(2, 2, 2));
  tube.f.erase(tube.f.begin(), tube.f.begin() + 4);
  tube.write_off(dir_ / "tube.off");
  s.bodies = {mesh_body("tube", (dir_ / "tube.off").string(), 17)};
  s.bodies[0].scale = Vec3::Constant(1e-3);
  s.bodies[0].translate = Vec3(0.5, 0, 0);
  msg = input_error_of([&] { run(s); });
  EXPECT_NE(msg.find("tube.off' is not closed: 8 border edges around 2 holes: 4 edges around "
                     "(0, 0, -1); 4 edges around (0, 0, 1) in the file's coordinates"),
            std::string::npos)
      << msg;

  s.bodies = {mesh_body("ghost", kData + "no_such_mesh.stl", 18)};
  msg = input_error_of([&] { run(s); });
  EXPECT_NE(msg.find("scene.toml:18: bodies.ghost.file"), std::string::npos) << msg;
  EXPECT_NE(msg.find("no_such_mesh.stl"), std::string::npos) << msg;
  // fit_lattice meets the file first when it fits the domain: same message.
  s.grid.domain_given = false;
  EXPECT_EQ(input_error_of([&] { fit_lattice(s); }), msg);
  s.grid.domain_given = true;

  for (const std::string f : {"garbage.stl", "garbage.off"}) {
    s.bodies = {mesh_body("junk", kData + f, 19)};
    msg = input_error_of([&] { run(s); });
    EXPECT_NE(msg.find("scene.toml:19: bodies.junk.file"), std::string::npos) << msg;
    EXPECT_NE(msg.find(f), std::string::npos) << msg;
  }

  // An empty file, an unknown extension, a mesh that intersects itself (two overlapping cubes).
  const fs::path empty = dir_ / "empty.obj";
  std::ofstream(empty).put('\n');
  s.bodies = {mesh_body("void", empty.string())};
  msg = input_error_of([&] { run(s); });
  EXPECT_NE(msg.find("empty.obj"), std::string::npos) << msg;
  EXPECT_NE(msg.find("bodies.void.file"), std::string::npos) << msg;

  const fs::path ply = dir_ / "thing.ply";
  std::ofstream(ply) << "ply\n";
  s.bodies = {mesh_body("thing", ply.string())};
  msg = input_error_of([&] { run(s); });
  EXPECT_NE(msg.find("unknown format '.ply'"), std::string::npos) << msg;

  TriMesh two = box_mesh(Vec3::Ones());
  TriMesh other = box_mesh(Vec3::Ones());
  for (auto& p : other.v) p += Vec3(0.5, 0.3, 0.2);
  for (auto t : other.f) {
    for (int& i : t) i += int(two.v.size());
    two.f.push_back(t);
  }
  two.v.insert(two.v.end(), other.v.begin(), other.v.end());
  const fs::path bad = dir_ / "overlapping_cubes.off";
  two.write_off(bad);
  s.bodies = {mesh_body("pair", bad.string())};
  msg = input_error_of([&] { run(s); });
  EXPECT_NE(msg.find("overlapping_cubes.off' intersects itself"), std::string::npos) << msg;
}

// ---------------------------------------------------------------------------------------------
// Speed (label `long`): 13.5 million particles from a primitive, and a mesh body.

TEST_F(VoxeliseMesh, LongSpeed) {
  // ctest runs Long tests only under the `long` label (by name); a bare ./unit_tests skips it.
  if (std::string(GTEST_FLAG_GET(filter)).find("Long") == std::string::npos)
    GTEST_SKIP() << "speed measurement: run with --gtest_filter='*Long*' or ctest -L long";
  using clock = std::chrono::steady_clock;
  // Sphere of radius 0.5 at h = 0.00676 (148 cells across), 2 per cell: ~13.5 million.
  Scene s = make_scene(3, 0.00676, Vec3(-0.51, -0.51, -0.51), Vec3(0.51, 0.51, 0.51));
  s.bodies = {sphere("ball", 0.5, Vec3::Zero())};
  const Lattice lat = make_lattice(s);
  std::vector<BodyReport> rep;
  auto t0 = clock::now();
  ColumnStore st = voxelise(s, lat, rep);
  double dt = std::chrono::duration<double>(clock::now() - t0).count();
  std::printf("primitive sphere: %zu particles in %.3f s = %.3g particles/s (%d threads)\n",
              st.size(), dt, st.size() / dt, omp_get_max_threads());
  EXPECT_GT(st.size(), 13000000u);
  EXPECT_LT(dt, 60.0);

  const auto paths = write_all_formats(icosphere(0.5, 5), dir_, "ico_speed");
  BodySpec b = mesh_body("ball", paths[1].string());  // binary STL
  s.bodies = {b};
  t0 = clock::now();
  const auto region = make_region(b, s);
  const double t_read = std::chrono::duration<double>(clock::now() - t0).count();
  std::printf("icosphere mesh (20480 triangles): read, checked, tree built in %.3f s\n", t_read);
  for (const double h : {0.0135, 0.00676}) {  // ~1.7 and ~13.5 million particles
    s.grid.cell_size = h;
    const Lattice lm = make_lattice(s);
    t0 = clock::now();
    st = voxelise(s, lm, rep);
    dt = std::chrono::duration<double>(clock::now() - t0).count();
    std::printf(
        "icosphere mesh: %zu particles in %.3f s = %.3g particles/s (includes reading "
        "and checking the mesh, %.3f s)\n",
        st.size(), dt, st.size() / dt, t_read);
    EXPECT_LT(dt, 60.0);
  }
}
