// Models of thousands of bodies (grains, fragments): body ids past 255 (stream format 1.2).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "mpm/core/columns.hpp"
#include "mpm/core/types.hpp"
#include "mpm/stream/stream.hpp"
#include "run_command.hpp"

namespace mpm {
namespace {

using namespace mpm::testing;

// 5 000 copper cubes, one cell each (one particle), on a lattice 3 cells apart, so that no two
// share a node: each flies free at its own velocity v_b = 0.1 m/s (b mod 10, b / 10 mod 10,
// -(b mod 7)), and a rigid plate (body 5 000, beyond the old 8-bit ids) moves below them. A
// particle alone on its cell's nodes moves exactly at its velocity (the grid velocity of one
// particle is its own; no stress arises), so after the run every particle has moved by
// v_b t to round-off (1e-12 m on 4 mm): the run kept every particle's body, and prep gave
// each body its own velocity.
TEST(ManyBodies, FiveThousandCubesRunAndKeepTheirBodies) {
  const auto dir = temp_dir("many_bodies");
  const int n = 5000, nx = 25, ny = 20;  // 25 x 20 x 10 cubes
  const double h = 1e-3, pitch = 3 * h;
  std::ofstream f(dir / "grains.toml");
  f << "[scene]\ndimension = 3\n[materials.copper]\ndensity = 8930\nyoungs_modulus = 117e9\n"
       "poisson_ratio = 0.35\n";
  for (int b = 0; b < n; ++b) {
    const int i = b % nx, j = (b / nx) % ny, k = b / (nx * ny);
    f << "[[bodies]]\nname = \"g" << b << "\"\nmaterial = \"copper\"\nshape = \"box\"\n"
      << "size = [" << h << ", " << h << ", " << h << "]\nparticles_per_cell = 1\n"
      << "translate = [" << (i + 0.5) * pitch << ", " << (j + 0.5) * pitch << ", "
      << (k + 2.5) * pitch << "]\nvelocity = [" << 0.1 * (b % 10) << ", " << 0.1 * ((b / 10) % 10)
      << ", " << -0.1 * (b % 7) << "]\n";
  }
  f << "[[bodies]]\nname = \"plate\"\nrigid = true\nshape = \"box\"\nsize = [0.075, 0.06, 0.001]\n"
       "translate = [0.0375, 0.03, 0.0015]\nvelocity = [0, 0, 0.5]\nparticles_per_cell = 1\n"
       "[grid]\ncell_size = 0.001\ndomain = { min = [-0.003, -0.003, 0], max = [0.078, 0.063, "
       "0.036] }\n[solver]\nend_time = 2e-6\n[output]\nframes = 1\n";
  f.close();
  const Result r = prep_and_run(dir / "grains.toml", "-q", dir / "out.mpm", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  Frame first, last;
  StreamVisitor v;
  v.frame = [&](Frame&& fr) { (first.columns.size() == 0 ? first : last) = std::move(fr); };
  read_stream((dir / "out.mpm").string(), v);
  ASSERT_EQ(first.columns.size(), std::size_t(n + 75 * 60));
  ASSERT_EQ(last.columns.size(), first.columns.size());
  const Column& body = last.columns.at("body");
  ASSERT_EQ(body.info().type, ScalarType::U32);
  const auto* b_of = body.as<std::uint32_t>();
  const auto* id0 = first.columns.at("id").as<std::uint32_t>();
  const auto* id1 = last.columns.at("id").as<std::uint32_t>();
  const auto* x0 = first.columns.at("x").as<Eigen::Vector3d>();
  const auto* x1 = last.columns.at("x").as<Eigen::Vector3d>();
  std::vector<std::size_t> at(first.columns.size());
  for (std::size_t i = 0; i < first.columns.size(); ++i) at[id0[i]] = i;
  const double t = last.time;
  ASSERT_GT(t, 1.9e-6);
  std::vector<int> seen(n + 1, 0);
  for (std::size_t i = 0; i < last.columns.size(); ++i) {
    const std::uint32_t b = b_of[i];
    ASSERT_LE(b, std::uint32_t(n));
    ++seen[b];
    const Eigen::Vector3d v =
        b == std::uint32_t(n)
            ? Eigen::Vector3d(0, 0, 0.5)
            : Eigen::Vector3d(0.1 * (b % 10), 0.1 * ((b / 10) % 10), -0.1 * (b % 7));
    EXPECT_NEAR((x1[i] - x0[at[id1[i]]] - v * t).norm(), 0, 1e-12) << "body " << b;
  }
  for (int b = 0; b < n; ++b) EXPECT_EQ(seen[b], 1) << "body " << b;
  EXPECT_EQ(seen[n], 75 * 60);
}

}  // namespace
}  // namespace mpm
