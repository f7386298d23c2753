// mpm-post render of a quarter model: the Taylor bar example as a quarter (slip faces x = 0 and
// y = 0 through the bar) at coarse cells. --view symmetry draws the whole bar's section in the
// plane y = 0 (the quarter and its images), symmetric about the bar's axis and twice as wide as
// the quarter's own section (--symmetry none); the band below the particles holds the scale bar.
#include <gtest/gtest.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include <vector>

#include "run_command.hpp"

namespace mpm {
namespace {

using namespace mpm::testing;
namespace fs = std::filesystem;

/// Non-white pixels per column of rows [y0, y1) (fractions of the height from the bottom) and
/// columns left of the colour bar (84% of the width).
std::vector<int> ink(const fs::path& png_path, double y0, double y1) {
  vtkNew<vtkPNGReader> png;
  png->SetFileName(png_path.c_str());
  png->Update();
  vtkImageData* img = png->GetOutput();
  int dims[3];
  img->GetDimensions(dims);
  std::vector<int> per_column(int(0.84 * dims[0]), 0);
  for (int y = int(y0 * dims[1]); y < int(y1 * dims[1]); ++y)
    for (int x = 0; x < int(per_column.size()); ++x) {
      const auto* px = static_cast<unsigned char*>(img->GetScalarPointer(x, y, 0));
      if (px[0] < 230 || px[1] < 230 || px[2] < 230) ++per_column[x];
    }
  return per_column;
}

/// The first and last columns with ink.
std::pair<int, int> span(const std::vector<int>& ink) {
  int first = -1, last = -1;
  for (int x = 0; x < int(ink.size()); ++x)
    if (ink[x] > 0) last = x, first = first < 0 ? x : first;
  return {first, last};
}

TEST(Cli, RenderShowsTheWholeSectionOfAQuarterModelWithAScaleBar) {
  const auto dir = temp_dir("render_symmetry");
  const fs::path scene = fs::path(MPM_EXAMPLES) / "taylor-bar" / "scene.toml";
  const fs::path out = dir / "quarter.mpm";
  Result r = run(prep + " " + scene.string() +
                     " --set grid.cell_size=\"1.52 mm\" --set grid.domain.min=\"0 0 0 mm\""
                     " --set grid.domain.max=\"12.16 12.16 27.36 mm\" --set boundary.x_min=slip"
                     " --set boundary.y_min=slip --set solver.end_time=\"20 us\" | " +
                     runner + " --threads 1 --progress none -o " + out.string(),
                 dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const fs::path whole = dir / "whole.png", cut = dir / "cut.png";
  r = run("env -u DISPLAY " + post + " render " + out.string() + " -o " + whole.string() +
              " --view symmetry --size 800x600",
          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  // The quarter's own particles cut at the same plane (all of them lie on its + side).
  r = run("env -u DISPLAY " + post + " render " + out.string() + " -o " + cut.string() +
              " --symmetry none --section \"y = 0\" --size 800x600",
          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  // The particles' viewport (above the band of the scale bar, below the title).
  const std::vector<int> w = ink(whole, 0.10, 0.92), c = ink(cut, 0.10, 0.92);
  const auto [w0, w1] = span(w);
  const auto [c0, c1] = span(c);
  ASSERT_GT(w1 - w0, 100);
  // Symmetric about the bar's axis: the left half holds as much ink as the right, to the
  // pixel columns the axis falls between (2%).
  long left = 0, right = 0;
  for (int x = w0; x <= w1; ++x) (2 * (x - w0) < w1 - w0 ? left : right) += w[x];
  EXPECT_NEAR(double(left) / double(right), 1.0, 0.02) << left << " " << right;
  // Both pictures fit their particles to the same height (the bar's length), so the whole
  // section is twice as wide as the quarter's, to a particle's radius on each side (5%).
  const auto height = [](const std::vector<int>& ink) {
    return *std::max_element(ink.begin(), ink.end());
  };
  const double ratio = double(w1 - w0) / height(w) / (double(c1 - c0) / height(c));
  EXPECT_NEAR(ratio, 2.0, 0.1) << w1 - w0 << " " << c1 - c0;
  // The scale bar and the caption in the band below the particles.
  const std::vector<int> band = ink(whole, 0.0, 0.09);
  long marks = 0;
  for (const int k : band) marks += k;
  EXPECT_GT(marks, 200) << "no scale bar or caption";
  // A section given badly names the option.
  r = run("env -u DISPLAY " + post + " render " + out.string() + " -o " + cut.string() +
              " --section \"w = 0\"",
          dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--section"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace mpm
