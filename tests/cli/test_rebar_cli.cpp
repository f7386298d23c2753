// Rebar through the tools: bad [[rebar]] input exits 2 naming the file, line and key; a ball
// through a reinforced slab on a graded grid: mpm-prep's rebar table, bars that erode (counted
// by mpm-post summary), rebar nodes never split, the bars as VTK line cells and in a picture.
#include <gtest/gtest.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "mpm/stream/stream.hpp"
#include "run_command.hpp"

namespace mpm {
namespace {

using namespace mpm::testing;
namespace fs = std::filesystem;

const fs::path kSlab = fs::path(MPM_TEST_DATA) / "cli" / "rebar_slab.toml";

/// The slab scene with `from` replaced by `to` (must occur), written to dir/name.
fs::path variant(const fs::path& dir, const std::string& name, const std::string& from,
                 const std::string& to) {
  std::string text = slurp(kSlab);
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  std::ofstream(dir / name) << text;
  return dir / name;
}

TEST(RebarCli, BadRebarInputExits2NamingFileLineAndKey) {
  const auto dir = temp_dir("rebar_bad");
  const std::string bar = "shape = \"layer\"\nbody = \"slab\"";
  struct Case {
    std::string name, from, to, says;
  };
  const std::vector<Case> cases = {
      {"zero_diameter.toml", "diameter = \"2 mm\"", "diameter = 0", "rebar.0.diameter"},
      {"unknown_material.toml", "material = \"steel\"\ndiameter", "material = \"rebar\"\ndiameter",
       "rebar.0.material: unknown material 'rebar'"},
      {"outside.toml", bar,
       "shape = \"bar\"\nstart = \"10 10 3 mm\"\nend = \"90 10 3 mm\"\nbody = \"slab\"",
       "rebar.0.end: the bar leaves the domain"},
      {"no_file.toml", bar, "shape = \"polyline\"\nfile = \"nowhere.txt\"\nbody = \"slab\"",
       "rebar.0.file: cannot read"},
  };
  for (const Case& c : cases) {
    fs::path scene = variant(dir, c.name, c.from, c.to);
    if (c.name != "zero_diameter.toml" && c.name != "unknown_material.toml") {
      // Keys the other shapes do not take go.
      std::string text = slurp(scene);
      for (const char* key :
           {"normal = \"z\"\n", "cover = \"2 mm\"\n", "pitch = \"8 mm\"\n", "count = [7, 7]\n"})
        text.erase(text.find(key), std::string(key).size());
      std::ofstream(scene) << text;
    }
    const Result r = run(prep + " " + scene.string() + " -o " + (dir / "m.mpm").string(), dir);
    EXPECT_EQ(r.status, 2) << c.name << "\n" << r.err;
    EXPECT_NE(r.err.find(scene.string() + ":"), std::string::npos) << c.name << "\n" << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << c.name << "\n" << r.err;
  }
}

/// Rebar nodes (material 254) in a CSV of mpm-post particles.
std::size_t rebar_nodes(const std::string& csv) {
  std::size_t n = 0;
  for (const double m : read_csv(csv).column("material")) n += m == 254;
  return n;
}

TEST(RebarCli, BallThroughReinforcedSlabOnAGradedGrid) {
  const auto dir = temp_dir("rebar_slab");
  const fs::path model = dir / "model.mpm", out = dir / "run.mpm";
  Result r = run(prep + " " + kSlab.string() + " -o " + model.string(), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  // 14 bars of 60 mm in 1.5 mm elements (half the 3 mm cell): 40 elements, 41 nodes a bar.
  EXPECT_NE(r.err.find("rebar.0        steel            14       560       574     1.5 mm"),
            std::string::npos)
      << r.err;
  r = run(runner + " " + model.string() + " --progress none --threads 1 -o " + out.string(), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  r = run(post + " summary " + out.string() + " --json", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(json_value(r.out, "rebar_elements"), 560);
  // The ball tears the bars below it: elements past 10% plastic strain eroded.
  const double eroded = json_value(r.out, "rebar_eroded");
  EXPECT_GT(eroded, 0) << r.out;
  // The history counts them as they go: its last row says as many.
  r = run(post + " history " + out.string() + " --columns rebar_eroded", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string last = r.out.substr(r.out.rfind('\n', r.out.size() - 2) + 1);
  EXPECT_EQ(std::stod(last), eroded) << r.out.substr(0, 200);
  // Particles split where the slab bulges into the fine level; the bar nodes did not.
  r = run(post + " particles " + model.string() + " --frame 0", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(rebar_nodes(r.out), 574u);
  const std::size_t n0 = std::count(r.out.begin(), r.out.end(), '\n');
  r = run(post + " particles " + out.string(), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(rebar_nodes(r.out), 574u);
  EXPECT_GT(std::size_t(std::count(r.out.begin(), r.out.end(), '\n')), n0 + 100) << "no split";
  // The bars as line cells with their state.
  r = run(post + " vtk " + out.string() + " -o " + (dir / "vtk").string(), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(slurp(dir / "vtk" / "frame_rebar.pvd").find("frame_rebar_0003.vtu"), std::string::npos);
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName((dir / "vtk" / "frame_rebar_0003.vtu").c_str());
  reader->Update();
  vtkUnstructuredGrid* g = reader->GetOutput();
  ASSERT_EQ(g->GetNumberOfCells(), 560);
  EXPECT_EQ(g->GetCellType(0), VTK_LINE);
  for (const char* name : {"axial_stress", "plastic_strain", "eroded"})
    ASSERT_NE(g->GetCellData()->GetArray(name), nullptr) << name;
  double range[2];
  g->GetCellData()->GetArray("eroded")->GetRange(range);
  EXPECT_EQ(range[1], 1.0);
  // The picture draws the bars (red, unlit: 204, 25, 25) over the particles.
  r = run("env -u DISPLAY " + post + " render " + out.string() + " -o " +
              (dir / "slab.png").string() + " --field speed --size 640x480",
          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  vtkNew<vtkPNGReader> png;
  png->SetFileName((dir / "slab.png").c_str());
  png->Update();
  vtkImageData* img = png->GetOutput();
  int dims[3];
  img->GetDimensions(dims);
  long red = 0;
  for (int y = 0; y < dims[1]; ++y)
    for (int x = 0; x < dims[0]; ++x) {
      const auto* px = static_cast<unsigned char*>(img->GetScalarPointer(x, y, 0));
      red += px[0] > 180 && px[1] < 60 && px[2] < 60;
    }
  EXPECT_GT(red, 200) << "no rebar drawn";
}

TEST(RebarCli, ModelsWithoutRebarStayStreams14) {
  // A scene without [[rebar]] writes a 1.4 stream (the same bytes as before rebar); with it,
  // the header says 1.5 (a reader of 1.4 skips the REBR records).
  const auto dir = temp_dir("rebar_version");
  const fs::path block = fs::path(MPM_TEST_DATA) / "cli" / "block.toml";
  Result r = run(prep + " " + block.string() + " -q -o " + (dir / "a.mpm").string(), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  r = run(prep + " " + kSlab.string() + " -q -o " + (dir / "b.mpm").string(), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(int(slurp(dir / "a.mpm")[10]), 4);
  EXPECT_EQ(int(slurp(dir / "b.mpm")[10]), 5);
}

/// The FRAM and REBR records of an intact stream, as bytes, and where its first CHKP ends.
std::vector<std::string> frames_and_rebar(const fs::path& p, std::uint64_t* first_checkpoint_end) {
  std::vector<std::string> out;
  const std::string bytes = slurp(p);
  StreamReader r(p.string());
  std::uint32_t type = 0;
  while (r.next(type)) {
    const std::uint64_t begin = r.record_offset();
    r.skip();
    if (type == std::uint32_t(RecordType::Frame) || type == std::uint32_t(RecordType::Rebar))
      out.push_back(bytes.substr(begin, r.offset() - begin));
    if (type == std::uint32_t(RecordType::Checkpoint) && first_checkpoint_end &&
        *first_checkpoint_end == 0)
      *first_checkpoint_end = r.offset();
  }
  return out;
}

TEST(RebarCli, RestartFromACheckpointContinuesBitwise) {
  // The slab on a uniform grid with a checkpoint every 10 us: the stream cut after the first
  // one and continued with --restart holds bitwise the frames and rebar of the whole run.
  const auto dir = temp_dir("rebar_restart");
  std::string scene = slurp(kSlab);
  scene.erase(scene.find("[[grid.levels]]"),
              scene.find("[solver]") - scene.find("[[grid.levels]]"));
  scene += "checkpoint = { time = \"10 us\" }\n";
  std::ofstream(dir / "uniform.toml") << scene;
  const fs::path full = dir / "full.mpm", cut = dir / "cut.mpm";
  Result r = prep_and_run(dir / "uniform.toml", "", full, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  std::uint64_t keep = 0;
  const std::vector<std::string> whole = frames_and_rebar(full, &keep);
  ASSERT_GT(keep, 0u) << "no checkpoint";
  ASSERT_EQ(whole.size(), 2u * 4 + 2);  // 4 frames and their REBR; a REBR before each CHKP
  std::ofstream(cut, std::ios::binary) << slurp(full).substr(0, keep);
  r = run(runner + " --restart " + cut.string() + " --progress none", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::vector<std::string> again = frames_and_rebar(cut, nullptr);
  ASSERT_EQ(again.size(), whole.size());
  for (std::size_t k = 0; k < whole.size(); ++k)
    EXPECT_TRUE(again[k] == whole[k]) << "record " << k;
}

}  // namespace
}  // namespace mpm
