// mpm-post vtk files read back with VTK's own readers; mpm-post render writes a PNG of the
// deformed block coloured by plastic strain on a machine with no display, and draws an
// axisymmetric frame as the whole section through the axis.
#include <gtest/gtest.h>
#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPointData.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <algorithm>
#include <vector>

#include "run_command.hpp"

namespace mpm {
namespace {

using namespace mpm::testing;
namespace fs = std::filesystem;

TEST(Cli, VtkSeriesReadsBackAndRenderWorksHeadless) {
  const auto dir = temp_dir("vtk_render");
  const fs::path scene = fs::path(MPM_TEST_DATA) / "cli" / "block.toml";
  const fs::path out = dir / "run.mpm";
  Result r = run(
      prep + " " + scene.string() + " | " + runner + " --progress none -o " + out.string(), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  r = run(post + " vtk " + out.string() + " -o " + (dir / "vtk").string() + " --name block", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string pvd = slurp(dir / "vtk" / "block.pvd");
  EXPECT_NE(pvd.find("block_0004.vtu"), std::string::npos) << pvd;
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName((dir / "vtk" / "block_0004.vtu").c_str());
  reader->Update();
  vtkUnstructuredGrid* g = reader->GetOutput();
  ASSERT_NE(g, nullptr);
  EXPECT_EQ(g->GetNumberOfPoints(), 4 * 4 * 4 * 8);  // 4 mm cube, 1 mm cells, 2^3 per cell
  for (const char* name : {"v", "sigma", "eps_p", "rho", "pressure", "von_mises", "id"})
    EXPECT_NE(g->GetPointData()->GetArray(name), nullptr) << name;
  EXPECT_EQ(g->GetPointData()->GetArray("sigma")->GetNumberOfComponents(), 6);
  // The block hit the wall at 100 m/s: yielded somewhere, compressed.
  double range[2];
  g->GetPointData()->GetArray("eps_p")->GetRange(range);
  EXPECT_GT(range[1], 0.0);

  r = run("env -u DISPLAY " + post + " render " + out.string() + " -o " +
              (dir / "block.png").string() + " --field eps_p --size 640x480",
          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  vtkNew<vtkPNGReader> png;
  png->SetFileName((dir / "block.png").c_str());
  png->Update();
  int dims[3];
  png->GetOutput()->GetDimensions(dims);
  EXPECT_EQ(dims[0], 640);
  EXPECT_EQ(dims[1], 480);
}

// Non-background pixels per column of the particles' viewport (left of the colour bar, below
// the title, above the band of the scale bar: the bottom 9%) of a rendered PNG.
std::vector<int> ink_per_column(const fs::path& png_path) {
  vtkNew<vtkPNGReader> png;
  png->SetFileName(png_path.c_str());
  png->Update();
  vtkImageData* img = png->GetOutput();
  int dims[3];
  img->GetDimensions(dims);
  const int w = int(0.84 * dims[0]), h = int(0.92 * dims[1]);  // rows run from the bottom
  std::vector<int> ink(w, 0);
  for (int y = int(0.09 * dims[1]) + 1; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const auto* px = static_cast<unsigned char*>(img->GetScalarPointer(x, y, 0));
      if (px[0] < 230 || px[1] < 230 || px[2] < 230) ++ink[x];
    }
  return ink;
}

// The V4 scene as a solid of revolution at t = 0: a plate (r 0..80 mm) and the sphere on the
// axis, a half disk in the r-z plane. Drawn mirrored (the default for axisymmetric frames),
// the picture is symmetric about the axis and its tallest column, through the sphere, is the
// middle one; with --half the sphere sits at the picture's left edge.
TEST(Cli, RenderDrawsAnAxisymmetricFrameAsTheWholeSection) {
  const auto dir = temp_dir("render_axisym");
  const fs::path out = dir / "axi.mpm";
  Result r = prep_and_run(fs::path(MPM_EXAMPLES) / "hypervelocity" / "axisym.toml",
                          "--set \"solver.end_time=0.1 us\"", out, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  for (const bool half : {false, true}) {
    const fs::path png = dir / (half ? "half.png" : "whole.png");
    r = run("env -u DISPLAY " + post + " render " + out.string() + " --frame 0 -o " + png.string() +
                " --field rho --size 800x600" + (half ? " --half" : ""),
            dir);
    ASSERT_EQ(r.status, 0) << r.err;
    const std::vector<int> ink = ink_per_column(png);
    int first = -1, last = -1;
    for (int x = 0; x < int(ink.size()); ++x)
      if (ink[x] > 0) last = x, first = first < 0 ? x : first;
    ASSERT_GT(last - first, 100) << "half " << half;
    const int tallest = int(std::max_element(ink.begin(), ink.end()) - ink.begin());
    const double span = last - first, where = (tallest - first) / span;
    if (!half) {
      EXPECT_NEAR(where, 0.5, 0.03) << "the sphere on the axis, in the middle";
      long left = 0, right = 0;
      for (int x = first; x <= last; ++x) (2 * (x - first) < last - first ? left : right) += ink[x];
      EXPECT_NEAR(double(left) / double(right), 1.0, 0.03) << left << " " << right;
    } else {
      EXPECT_LT(where, 0.03) << "the sphere at the left edge (the axis)";
    }
  }
}

}  // namespace
}  // namespace mpm
