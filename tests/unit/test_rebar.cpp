// Rebar (004, section 2: HFEMP): the [[rebar]] scene tables, their discretisation into truss
// elements whose nodes are particles, the REBR record of the stream, and the 1D return mapping.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "mpm/core/error.hpp"
#include "mpm/prep/rebar.hpp"
#include "mpm/scene/particles.hpp"
#include "mpm/scene/rebar_elements.hpp"
#include "mpm/solver/explicit/rebar.hpp"
#include "mpm/stream/stream.hpp"

namespace mpm {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;

const std::string kHead = R"(
[materials.concrete]
density = 2440
youngs_modulus = "30 GPa"
poisson_ratio = 0.2
[materials.steel]
density = 7500
youngs_modulus = "210 GPa"
poisson_ratio = 0.284
[materials.steel.strength]
model = "j2"
A = "235 MPa"
[[bodies]]
name = "slab"
material = "concrete"
shape = "box"
size = "100 100 40 mm"
translate = "50 50 20 mm"
[grid]
cell_size = "5 mm"
[solver]
end_time = "1 us"
)";

Scene scene_with(const std::string& rebar, const std::string& dir = "") {
  return parse_scene(kHead + rebar, "s.toml", dir, {});
}

/// The message of the InputError parsing throws (empty when none).
std::string parse_error(const std::string& rebar) {
  try {
    scene_with(rebar);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

ColumnStore model_columns() {
  ColumnStore c;
  c.add({col::id, ScalarType::U32, 1, "-"});
  c.add(body_column(1));
  c.add({col::material, ScalarType::U8, 1, "-"});
  c.add({col::x, ScalarType::F64, 3, "m"});
  c.add({col::v, ScalarType::F64, 3, "m/s"});
  c.add({col::m, ScalarType::F64, 1, "kg"});
  c.add({col::rho, ScalarType::F64, 1, "kg/m^3"});
  return c;
}

Lattice slab_lattice() {
  Lattice l;
  l.dim = 3;
  l.origin = Vec3(-0.01, -0.01, -0.01);
  l.h = 0.005;
  l.cells = {24, 24, 12};
  return l;
}

TEST(RebarScene, BadInputNamesFileLineAndKey) {
  const std::string bar = R"(
[[rebar]]
shape = "bar"
material = "steel"
start = "5 50 30 mm"
end = "95 50 30 mm"
)";
  std::string e = parse_error(bar + "diameter = 0\n");
  EXPECT_NE(e.find("s.toml:"), std::string::npos) << e;
  EXPECT_NE(e.find("rebar.0.diameter"), std::string::npos) << e;
  e = parse_error(R"(
[[rebar]]
shape = "bar"
material = "rubber"
diameter = "6 mm"
start = "5 50 30 mm"
end = "95 50 30 mm"
)");
  EXPECT_NE(e.find("rebar.0.material"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown material 'rubber'"), std::string::npos) << e;
  e = parse_error(bar + "diameter = \"6 mm\"\npitch = \"25 mm\"\n");
  EXPECT_NE(e.find("rebar.0.pitch"), std::string::npos) << e;
  // A layer needs the body whose box places it.
  e = parse_error(R"(
[[rebar]]
shape = "layer"
material = "steel"
diameter = "6 mm"
normal = "z"
offset = "20 mm"
pitch = "25 mm"
count = [4, 4]
)");
  EXPECT_NE(e.find("rebar.0: missing required key 'body'"), std::string::npos) << e;
}

TEST(RebarScene, OverridesSelectAnEntryByIndex) {
  const std::string bar = R"(
[[rebar]]
shape = "bar"
material = "steel"
diameter = "6 mm"
start = "5 50 30 mm"
end = "95 50 30 mm"
)";
  const Scene s = parse_scene(kHead + bar, "s.toml", "",
                              {"rebar.0.diameter=4mm", "rebar.0.erosion_strain=0.2"});
  EXPECT_DOUBLE_EQ(s.rebars[0].diameter, 4e-3);
  EXPECT_DOUBLE_EQ(s.rebars[0].erosion_strain, 0.2);
  try {
    parse_scene(kHead + bar, "s.toml", "", {"rebar.1.diameter=4mm"});
    ADD_FAILURE() << "a missing entry was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no [[rebar]] entry with index 1"), std::string::npos)
        << e.what();
  }
}

TEST(RebarScene, MassOfTheNodesIsTheBarsMass) {
  // A layer of 4 x 4 bars across the 100 mm slab and one 90 mm bar, elements of at most
  // 2.5 mm (half the cell): the nodes' lumped masses rho A L / 2 per element end add up to
  // rho A L_total to round-off.
  const Scene s = scene_with(R"(
[[rebar]]
shape = "layer"
body = "slab"
material = "steel"
diameter = "5.59 mm"
normal = "z"
cover = "10 mm"
pitch = "25 mm"
count = [4, 4]
[[rebar]]
shape = "bar"
material = "steel"
diameter = "6 mm"
start = "5 50 30 mm"
end = "95 50 30 mm"
element_length = "4 mm"
)");
  ColumnStore cols = model_columns();
  std::vector<RebarReport> rep;
  const ColumnStore el =
      discretise_rebar(s, slab_lattice(), {Vec3(0, 0, 0)}, {Vec3(0.1, 0.1, 0.04)}, cols, rep);
  ASSERT_EQ(rep.size(), 2u);
  EXPECT_EQ(rep[0].bars, 8u);
  EXPECT_EQ(rep[0].elements, 8u * 40);  // 100 mm in 2.5 mm elements
  EXPECT_EQ(rep[0].nodes, 8u * 41);
  EXPECT_EQ(rep[1].elements, 23u);  // ceil(90 / 4)
  const double A0 = 0.25 * kPi * 5.59e-3 * 5.59e-3, A1 = 0.25 * kPi * 36e-6;
  // (the layer's bars end 1e-9 h short of the domain's upper face: 5e-11 of their length)
  EXPECT_NEAR(rep[0].exact_mass / (7500 * A0 * 0.8), 1.0, 1e-9);
  EXPECT_NEAR(rep[1].exact_mass / (7500 * A1 * 0.09), 1.0, 1e-12);
  for (const auto& r : rep) EXPECT_NEAR(r.mass / r.exact_mass, 1.0, 1e-12);
  // The layer's plane: the slab's lower face + cover + d / 2; nodes are rebar nodes.
  ASSERT_EQ(cols.size(), 8u * 41 + 24);
  const auto* x = cols.get<Vec3>(col::x);
  const auto* mat = cols.get<std::uint8_t>(col::material);
  EXPECT_NEAR(x[0].z(), 0.010 + 0.5 * 5.59e-3, 1e-15);
  for (std::size_t i = 0; i < cols.size(); ++i) EXPECT_EQ(mat[i], kRebarNode);
  EXPECT_EQ(el.size(), 8u * 40 + 23);
  // Bars parallel to x at y = 12.5, 37.5, ... mm (centred on the slab).
  EXPECT_NEAR(x[0].y(), 0.0125, 1e-15);
}

TEST(RebarScene, BarsOnSymmetryPlanesCarryTheirShare) {
  // A quarter model (slip faces x = 0 and y = 0 are mirror planes): a bar lying in one plane
  // is half a bar of the whole model, one on both planes (their intersection) a quarter; a bar
  // off the planes is whole.
  const Scene s = scene_with(R"(
[boundary]
x_min = "slip"
y_min = "slip"
[[rebar]]
shape = "bar"
material = "steel"
diameter = "6 mm"
start = "0 10 5 mm"
end = "0 50 5 mm"
[[rebar]]
shape = "bar"
material = "steel"
diameter = "6 mm"
start = "0 0 5 mm"
end = "0 0 25 mm"
[[rebar]]
shape = "bar"
material = "steel"
diameter = "6 mm"
start = "10 10 5 mm"
end = "10 50 5 mm"
)");
  Lattice lat = slab_lattice();
  lat.origin = Vec3(0, 0, -0.01);
  ColumnStore cols = model_columns();
  std::vector<RebarReport> rep;
  const ColumnStore el =
      discretise_rebar(s, lat, {Vec3::Zero()}, {Vec3(0.1, 0.1, 0.04)}, cols, rep);
  const double A = 0.25 * kPi * 36e-6;
  EXPECT_NEAR(rep[0].exact_mass / (7500 * A * 0.04), 0.5, 1e-12);
  EXPECT_NEAR(rep[1].exact_mass / (7500 * A * 0.02), 0.25, 1e-12);
  EXPECT_NEAR(rep[2].exact_mass / (7500 * A * 0.04), 1.0, 1e-12);
  for (const auto& r : rep) EXPECT_NEAR(r.mass / r.exact_mass, 1.0, 1e-12);
  const double* area = el.get<double>(rebar_col::area);
  EXPECT_DOUBLE_EQ(area[0], 0.5 * A);
  EXPECT_DOUBLE_EQ(area[el.size() - 1], A);
}

TEST(RebarScene, OutsideTheDomainAndBadPolylinesAreRefused) {
  Scene s = scene_with(R"(
[[rebar]]
shape = "bar"
material = "steel"
diameter = "6 mm"
start = "5 50 30 mm"
end = "150 50 30 mm"
)");
  ColumnStore cols = model_columns();
  std::vector<RebarReport> rep;
  const std::vector<Vec3> lo{Vec3::Zero()}, hi{Vec3(0.1, 0.1, 0.04)};
  try {
    discretise_rebar(s, slab_lattice(), lo, hi, cols, rep);
    ADD_FAILURE() << "a bar outside the domain was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("rebar.0.end"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("leaves the domain"), std::string::npos) << e.what();
  }
  const fs::path dir = fs::temp_directory_path() / "mpm_rebar_unit";
  fs::create_directories(dir);
  std::ofstream(dir / "bad.txt") << "0.01 0.05 0.02\n0.05 0.05\n";
  std::ofstream(dir / "good.txt") << "# two polylines\n0.01 0.05 0.02\n0.05 0.05 0.02\n"
                                     "0.05 0.09 0.02\n\n0.02 0.02 0.01\n0.08 0.02 0.01\n";
  const std::string poly =
      "[[rebar]]\nshape = \"polyline\"\nmaterial = \"steel\"\n"
      "diameter = \"6 mm\"\nfile = ";
  for (const auto& [file, expect] : std::vector<std::pair<std::string, std::string>>{
           {"\"missing.txt\"", "rebar.0.file"}, {"\"bad.txt\"", "bad.txt:2"}}) {
    s = scene_with(poly + file + "\n", dir.string());
    try {
      discretise_rebar(s, slab_lattice(), lo, hi, cols, rep);
      ADD_FAILURE() << file;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << e.what();
    }
  }
  s = scene_with(poly + "\"good.txt\"\n", dir.string());
  ColumnStore c2 = model_columns();
  discretise_rebar(s, slab_lattice(), lo, hi, c2, rep);
  EXPECT_EQ(rep[0].bars, 2u);
  EXPECT_NEAR(rep[0].length, 0.04 + 0.04 + 0.06, 1e-15);
  EXPECT_EQ(rep[0].nodes, 1u + 16 + 16 + 1 + 24);  // a polyline's corner node is shared
  fs::remove_all(dir);
}

TEST(RebarStream, ElementRecordRoundTrip) {
  // The REBR record keeps every column bitwise; a reader that does not ask for it (an older
  // one) skips it and reads the frames around it. A stream without REBR stays a 1.4 stream.
  const fs::path p = fs::temp_directory_path() / "mpm_rebar_stream.mpm";
  ColumnStore el = rebar_element_columns();
  el.resize(3);
  auto* nodes = reinterpret_cast<std::uint32_t*>(el.at(rebar_col::nodes).data());
  auto* eps = el.get<double>(rebar_col::eps_pbar);
  auto* er = el.get<std::uint8_t>(rebar_col::eroded);
  for (int k = 0; k < 3; ++k) nodes[2 * k] = 10 + k, nodes[2 * k + 1] = 11 + k;
  eps[1] = 0.27, er[1] = 1;
  el.get<double>(rebar_col::area)[2] = 2.45e-5;
  {
    StreamWriter w(p.string(), kStreamVersionMinor);
    Frame f;
    f.step = 7;
    f.columns = model_columns();
    w.write_frame(f);
    Frame e;
    e.step = 7;
    e.time = 1e-6;
    std::swap(e.columns, el);
    w.write_rebar(e);
    std::swap(e.columns, el);
    w.write_frame(f);
    w.write_end(0, "done");
  }
  std::vector<Frame> got;
  std::size_t frames = 0;
  StreamVisitor v;
  v.frame = [&](Frame&&) { ++frames; };
  v.rebar = [&](Frame&& f) { got.push_back(std::move(f)); };
  StreamSummary s = read_stream(p.string(), v);
  EXPECT_EQ(s.damage, "");
  EXPECT_EQ(frames, 2u);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].step, 7);
  EXPECT_EQ(got[0].time, 1e-6);
  for (const Column& c : el.columns()) {
    const Column* r = got[0].columns.find(c.info().name);
    ASSERT_NE(r, nullptr) << c.info().name;
    EXPECT_EQ(r->info().type, c.info().type);
    EXPECT_EQ(r->info().components, c.info().components);
    EXPECT_EQ(std::memcmp(r->data(), c.data(), c.bytes()), 0) << c.info().name;
  }
  v.rebar = nullptr;  // a reader without a use for it
  frames = 0;
  s = read_stream(p.string(), v);
  EXPECT_EQ(s.damage, "");
  EXPECT_EQ(frames, 2u);
  std::ifstream in(p, std::ios::binary);
  char h[16];
  in.read(h, 16);
  EXPECT_EQ(h[10], 5);  // the minor version a REBR record needs
  fs::remove(p);
}

TEST(RebarTruss, ReturnMappingIsIdealElasticPlastic) {
  // E = 210 GPa, sigma_y = 235 MPa: yield at eps = sigma_y / E = 1.119e-3.
  const double E = 210e9, sy = 235e6;
  double ep = 0, epbar = 0;
  EXPECT_DOUBLE_EQ(truss_stress(1e-3, E, sy, ep, epbar), E * 1e-3);
  EXPECT_EQ(ep, 0.0);
  EXPECT_DOUBLE_EQ(truss_stress(3e-3, E, sy, ep, epbar), sy);
  EXPECT_NEAR(ep, 3e-3 - sy / E, 1e-18);
  // Unloading is elastic, from the plastic strain; compression yields at -sigma_y.
  EXPECT_NEAR(truss_stress(2e-3, E, sy, ep, epbar), sy - E * 1e-3, 1e-3);
  EXPECT_DOUBLE_EQ(truss_stress(-5e-3, E, sy, ep, epbar), -sy);
  EXPECT_NEAR(ep, -5e-3 + sy / E, 1e-18);
  EXPECT_NEAR(epbar, (3e-3 - sy / E) + (3e-3 - sy / E) + (5e-3 - sy / E), 1e-15);
}

}  // namespace
}  // namespace mpm
