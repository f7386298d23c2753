// Graded grids end to end: mpm-prep reports the levels and writes the grid into the model,
// mpm-run splits particles and writes the grid into the result, mpm-post vtk writes the grid
// as a .vtu with a level field, mpm-post profile extracts a field along a line; bad level
// boxes stop mpm-prep with file, line and key and exit status 2.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "run_command.hpp"

namespace mpm {
namespace {

using namespace mpm::testing;
namespace fs = std::filesystem;

const fs::path kBlock = fs::path(MPM_TEST_DATA) / "cli" / "block.toml";

/// block.toml with level boxes appended after its [grid] table.
fs::path graded_block(const fs::path& dir, const std::string& levels) {
  std::string text = slurp(kBlock);
  const std::string grid = "domain = { min = \"-4 -4 0 mm\", max = \"4 4 8 mm\" }\n";
  const auto at = text.find(grid);
  EXPECT_NE(at, std::string::npos);
  text.insert(at + grid.size(), levels);
  const fs::path p = dir / "graded.toml";
  std::ofstream(p) << text;
  return p;
}

const std::string kLevel =
    "\n[[grid.levels]]\nlevel = 2\nmin = \"-3 -3 0 mm\"\nmax = \"3 3 2 mm\"\n";

TEST(GradedCli, PipelineWritesTheGridAndSplits) {
  const auto dir = temp_dir("graded_pipeline");
  const fs::path scene = graded_block(dir, kLevel);
  Result r = run(prep + " " + scene.string() + " -o " + (dir / "model.mpm").string(), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("graded grid:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("level 2: cell 0.5 mm"), std::string::npos) << r.err;
  // The block fills both levels: the table gives both spacings (half of each level's cell).
  EXPECT_NE(r.err.find("0.5 / 0.25 mm"), std::string::npos) << r.err;
  r = run(runner + " " + (dir / "model.mpm").string() + " -o " + (dir / "run.mpm").string() +
              " --stats --progress none",
          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  // The block falls 0.4 mm into the level-2 box: its coarse particles there split.
  EXPECT_NE(r.err.find("graded grid: 2 levels"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("split_particles"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find(" 0 particles split"), std::string::npos) << r.err;
  r = run(post + " vtk " + (dir / "run.mpm").string() + " -o " + (dir / "vtk").string(), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "vtk" / "frame_grid_0000.vtu"));
  EXPECT_TRUE(fs::exists(dir / "vtk" / "frame_grid.pvd"));
  const std::string vtu = slurp(dir / "vtk" / "frame_grid_0000.vtu");
  EXPECT_NE(vtu.find("Name=\"level\""), std::string::npos);
  EXPECT_NE(vtu.find("Name=\"hanging\""), std::string::npos);
  EXPECT_NE(r.err.find("1 graded grid(s)"), std::string::npos) << r.err;
  // The model stream holds the grid too.
  r = run(post + " vtk " + (dir / "model.mpm").string() + " -o " + (dir / "model_vtk").string(),
          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "model_vtk" / "frame_grid_0000.vtu"));
}

// Each level fills a face on its own lattice: the block (z from 0.3 to 4.3 mm) stands half in
// a level-2 box of 0.5 mm cells (x < 0, z < 2 mm), whose particles (0.25 mm apart, from z = 0)
// fill its bottom from 0.25 mm, and half in level 1 (1 mm cells, 0.5 mm apart), which fills
// it from 0.5 mm. mpm-prep lists both, and the top (level 1 only) filled to 4.5 mm.
TEST(GradedCli, PrepSaysWhereEachLevelPutsAFace) {
  const auto dir = temp_dir("graded_faces");
  const fs::path scene =
      graded_block(dir, "\n[[grid.levels]]\nlevel = 2\nmin = \"-3 -3 0 mm\"\nmax = \"0 3 2 mm\"\n");
  Result r = run(prep + " " + scene.string() + " --set \"bodies.block.translate=0 0 2.3 mm\" -o " +
                     (dir / "model.mpm").string(),
                 dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("block: face z = 0.3 mm filled to 0.5 mm (0.2 mm short of it; particles "
                       "0.5 mm apart)"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("block: face z = 0.3 mm filled to 0.25 mm (0.05 mm beyond it; particles "
                       "0.25 mm apart)"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("block: face z = 4.3 mm filled to 4.5 mm (0.2 mm beyond it; particles "
                       "0.5 mm apart)"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("face z = 4.3 mm filled to 4.25"), std::string::npos) << r.err;
  // Its bottom's place against each level's node planes, 0.3 mm above z = 0 in both levels (0.3
  // of level 1's cells, 0.6 of level 2's): it faces the wall z = 0. The top faces nothing.
  EXPECT_NE(r.err.find("block: face z = 0.3 mm lies 0.3 mm above the node plane z = 0 mm (0.3 of "
                       "level 1's 1 mm cells)"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("block: face z = 0.3 mm lies 0.3 mm above the node plane z = 0 mm (0.6 of "
                       "level 2's 0.5 mm cells)"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("face z = 4.3 mm lies"), std::string::npos) << r.err;
}

TEST(GradedCli, ProfileAlongALine) {
  const auto dir = temp_dir("graded_profile");
  const fs::path scene = graded_block(dir, kLevel);
  ASSERT_EQ(run(prep + " " + scene.string() + " | " + runner + " --progress none -o " +
                    (dir / "run.mpm").string(),
                dir)
                .status,
            0);
  const std::string file = (dir / "run.mpm").string();
  Result r =
      run(post + " profile " + file + " --field sigma --component zz --along z --bins 4", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.rfind("time,s,value,min,max,count,weight\n", 0), 0u) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 5) << r.out;  // header + 4 bins
  r = run(post + " profile " + file +
              " --field speed --from \"0 0 0 mm\" --to \"0 0 4 mm\" --radius \"1 mm\" --time 2us "
              "--time 4us --json",
          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("\"profiles\": [{\"time\": 2e-06"), std::string::npos)
      << r.out.substr(0, 300);
  EXPECT_NE(r.out.find("{\"time\": 4e-06"), std::string::npos);
  r = run(post + " profile " + file + " --field nope", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("unknown field 'nope' (available: "), std::string::npos) << r.err;
  r = run(post + " profile " + file + " --grid --field sigma", dir);  // graded: no single grid
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--grid: the run's grid is graded"), std::string::npos) << r.err;
  EXPECT_EQ(run(post + " profile --help", dir).status, 0);
}

TEST(GradedCli, BadLevelBoxesAreReportedWithFileLineAndKey) {
  const auto dir = temp_dir("graded_bad");
  // Off the level-1 lattice (1 mm from the domain's corner).
  fs::path scene = graded_block(
      dir, "\n[[grid.levels]]\nlevel = 2\nmin = \"-2.5 -3 0 mm\"\nmax = \"3 3 2 mm\"\n");
  Result r = run(prep + " " + scene.string() + " -o " + (dir / "m.mpm").string(), dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find(
                "graded.toml:31: grid.levels.0.min: a level-2 box must lie on the level-1 lattice"),
            std::string::npos)
      << r.err;
  // A level-3 box against the side of the level-2 box.
  scene = graded_block(
      dir, kLevel + "\n[[grid.levels]]\nlevel = 3\nmin = \"-3 -1 0 mm\"\nmax = \"-2 1 1 mm\"\n");
  r = run(prep + " " + scene.string() + " -o " + (dir / "m.mpm").string(), dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("grid.levels.1: the level-3 box"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("closer than one level-2 cell"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace mpm
