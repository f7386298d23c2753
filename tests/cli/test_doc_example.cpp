// The plane-strain example of docs/scene.md (issue 26, item 10) runs as the text under it says:
// the plate at rest until the disk comes within a cell, the fixed face under the plate takes
// the load, the wall's impulse is the momentum the bodies lose, and the disk bounces back.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "mpm/stream/stream.hpp"
#include "run_command.hpp"

namespace mpm {
namespace {

using namespace mpm::testing;
namespace fs = std::filesystem;

/// The ```toml block of docs/scene.md that starts with `first_line`.
std::string doc_block(const std::string& first_line) {
  std::ifstream in(std::string(MPM_TEST_DATA) + "/../../docs/scene.md");
  std::string line, block;
  bool inside = false, wanted = false;
  while (std::getline(in, line)) {
    if (!inside && line == "```toml") {
      inside = true;
      block.clear();
    } else if (inside && line == "```") {
      if (wanted) return block;
      inside = false;
    } else if (inside) {
      if (block.empty()) wanted = line == first_line;
      block += line + "\n";
    }
  }
  return "";
}

// The disk (radius 2 mm, 100 m/s) starts 0.5 mm above the plate, on a 0.25 mm grid with 2 x 2
// particles a cell: its lowest particle centre (2.5625 mm) first shares a grid node with the
// plate's top particles (nodes up to y = 2 mm) when it enters the cell below 2.25 mm, after
// 0.3125 mm of travel, 3.125 us. Until then the plate's particles see no force at all, so their
// kinetic energy and momentum are exactly 0, and so is the wall's force; we check t < 2.5 us.
// The fixed face is the only outside force, so the bodies' momentum changes by the wall's
// impulse: summed with the history's own rows (one per step, the step's force over the step),
// bound 2% for the first-order sum over rows whose dt varies.
TEST(DocExample, PlaneStrainDiskOntoPlateRunsAsDescribed) {
  const std::string text = doc_block("# Example: disk onto a plate, plane strain");
  ASSERT_FALSE(text.empty()) << "docs/scene.md lost its plane-strain example";
  const fs::path dir = temp_dir("doc_disk");
  { std::ofstream(dir / "disk.toml") << text; }
  const fs::path out = dir / "disk.mpm";
  Result r = run(prep + " " + (dir / "disk.toml").string() + " | " + runner +
                     " --threads 1 --progress none -o " + out.string(),
                 dir);
  ASSERT_EQ(r.status, 0) << r.err;
  HistoryBlock h;
  StreamVisitor v;
  v.want_frames = false;
  v.history = [&](HistoryBlock&& b) {
    if (h.names.empty()) h.names = b.names;
    h.values.insert(h.values.end(), b.values.begin(), b.values.end());
  };
  ASSERT_TRUE(read_stream(out.string(), v).damage.empty());
  auto column = [&](const std::string& name) {
    const auto it = std::find(h.names.begin(), h.names.end(), name);
    EXPECT_NE(it, h.names.end()) << name;
    std::vector<double> c;
    if (it == h.names.end()) return c;
    const std::size_t j = std::size_t(it - h.names.begin()), n = h.names.size();
    for (std::size_t k = 0; k < h.rows(); ++k) c.push_back(h.values[k * n + j]);
    return c;
  };
  const auto t = column("time"), dt = column("dt"), kp = column("kinetic_plate"),
             pp = column("momentum_plate_y"), pd = column("momentum_disk_y"),
             py = column("momentum_y"), f = column("force_y_min");
  ASSERT_GT(t.size(), 100u);
  double impulse = 0, peak = 0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (t[k] < 2.5e-6) {
      ASSERT_EQ(kp[k], 0.0) << "t = " << t[k];
      ASSERT_EQ(pp[k], 0.0) << "t = " << t[k];
      ASSERT_EQ(f[k], 0.0) << "t = " << t[k];
    }
    impulse += f[k] * dt[k];
    peak = std::max(peak, std::abs(f[k]));
  }
  EXPECT_GT(peak, 0.0) << "the fixed face under the plate takes load";
  const double lost = py.back() - py.front();
  EXPECT_NEAR(std::abs(impulse), std::abs(lost), 0.02 * std::abs(lost))
      << "impulse " << impulse << " N s/m against the momentum change " << lost;
  // The elastic disk bounces back (measured 93% of its momentum, upward), leaving some of its
  // energy in the plate: it ends moving up, slower than it came.
  const auto kd = column("kinetic_disk");
  EXPECT_GT(pd.back(), 0.5 * std::abs(pd.front())) << "the disk bounces back";
  EXPECT_LT(kd.back(), kd.front()) << "and leaves energy in the plate";
}

}  // namespace
}  // namespace mpm
