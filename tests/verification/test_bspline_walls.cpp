// Walls on the quadratic B-spline grid (grid.shape = "bspline"): a constrained face is a plane
// of symmetry, its ghost nodes the mirror images of the nodes inside (GridNodes::GhostNode).
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "mpm/grid/bspline_grid.hpp"
#include "mpm/prep/initial_fields.hpp"
#include "mpm/prep/voxelise.hpp"
#include "mpm/solver/explicit/explicit_solver.hpp"

namespace mpm {
namespace {

// A copper block (elastic-plastic, Mie-Grueneisen) strikes a slip wall obliquely, and, in a
// second run without the wall, its mirror image. The wall run holds its face's normal velocity
// and mirrors the ghost nodes; the mirror run has no boundary at all. Plane strain.
const char* kBlock = R"toml(
[scene]
dimension = 2
[materials.copper]
density = "8930 kg/m^3"
youngs_modulus = "117 GPa"
poisson_ratio = 0.35
[materials.copper.strength]
model = "johnson-cook"
A = "157 MPa"
B = "425 MPa"
n = 1.0
C = 0.0
[materials.copper.eos]
model = "mie-gruneisen"
c0 = "3940 m/s"
s = 1.49
gamma0 = 1.96
[[bodies]]
name = "block"
material = "copper"
shape = "box"
size = "4 8 mm"
translate = "0 4 mm"
velocity = "40 -190 m/s"
MIRROR
[grid]
cell_size = "0.5 mm"
shape = "bspline"
DOMAIN
[solver]
end_time = "20 us"
)toml";

std::vector<Vec<2>> run(const std::string& mirror, const std::string& domain) {
  std::string text = kBlock;
  text.replace(text.find("MIRROR"), 6, mirror);
  text.replace(text.find("DOMAIN"), 6, domain);
  const Scene s = parse_scene(text, "block.toml", "", {});
  const Lattice lat = make_lattice(s);
  std::vector<BodyReport> report;
  ColumnStore cols = voxelise(s, lat, report);
  apply_initial_fields(s, cols);
  ExplicitSolver<BsplineGrid<2>> solver(s, BsplineGrid<2>(lat, s.boundary), cols,
                                        ScatterStrategy::Colored);
  while (solver.time() < s.solver.end_time)
    solver.step(std::min(solver.stable_dt(), s.solver.end_time - solver.time()));
  // The block's particles by id (the block is body 0 and numbered first in both runs).
  const auto* x = cols.get<Vec<2>>(col::x);
  const auto* id = cols.get<std::uint32_t>(col::id);
  const auto* body = cols.get<std::uint8_t>(col::body);
  std::vector<Vec<2>> out(cols.size());
  std::size_t n = 0;
  for (std::size_t i = 0; i < cols.size(); ++i)
    if (body[i] == 0) out[id[i]] = x[i], n = std::max<std::size_t>(n, id[i] + 1);
  out.resize(n);
  return out;
}

// After 20 us (the block flattened against the wall, its foot sliding along it) every particle
// of the block is where its counterpart of the mirrored pair is, to round-off: the sums fold in
// another order (measured 7e-18 m; 1e-12 m is 1e-10 of the block's 8 mm).
TEST(BsplineWalls, ASlipFaceActsAsTheBodysMirrorImage) {
  const auto wall = run("",
                        "domain = { min = \"-8 0 mm\", max = \"8 12 mm\" }\n[boundary]\n"
                        "y_min = \"slip\"");
  const auto pair =
      run("[[bodies]]\nname = \"image\"\nmaterial = \"copper\"\nshape = \"box\"\n"
          "size = \"4 8 mm\"\ntranslate = \"0 -4 mm\"\nvelocity = \"40 190 m/s\"",
          "domain = { min = \"-8 -12 mm\", max = \"8 12 mm\" }");
  ASSERT_EQ(wall.size(), pair.size());
  ASSERT_GT(wall.size(), 100u);
  double worst = 0, lowest = 1;
  for (std::size_t i = 0; i < wall.size(); ++i) {
    worst = std::max(worst, (wall[i] - pair[i]).norm());
    lowest = std::min(lowest, wall[i][1]);
  }
  std::printf("largest distance between the wall run and the mirrored pair: %.3g m\n", worst);
  EXPECT_LT(worst, 1e-12) << "m";
  EXPECT_LT(lowest, 0.5e-3) << "the block reached the wall";
  EXPECT_GE(lowest, 0.0) << "and did not pass it";
}

}  // namespace
}  // namespace mpm
