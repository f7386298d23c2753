// mpm-post vtk files read back with VTK's own readers; mpm-post render writes a PNG of the
// deformed block coloured by plastic strain on a machine with no display.
#include <gtest/gtest.h>
#include <vtkPNGReader.h>
#include <vtkPointData.h>
#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include "run_command.hpp"

namespace mpm {
namespace {

using namespace mpm::testing;
namespace fs = std::filesystem;

TEST(Cli, VtkSeriesReadsBackAndRenderWorksHeadless) {
  const auto dir = temp_dir("vtk_render");
  const fs::path scene = fs::path(MPM_TEST_DATA) / "cli" / "block.toml";
  const fs::path out = dir / "run.mpm";
  Result r = run(prep + " " + scene.string() + " | " + runner + " --progress none -o " + out.string(), dir);
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

  r = run("env -u DISPLAY " + post + " render " + out.string() + " -o " + (dir / "block.png").string() +
              " --field eps_p --size 640x480",
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

}  // namespace
}  // namespace mpm
