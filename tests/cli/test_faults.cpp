// Faults in the user's files met by the tools themselves: a scene with a key or a table given
// twice, a mesh with holes. Each is refused with exit 2 and a message that names the file, the
// line (scene) or where the holes are (mesh).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "run_command.hpp"

namespace mpm {
namespace {

using namespace mpm::testing;
namespace fs = std::filesystem;

const fs::path kBlock = fs::path(MPM_TEST_DATA) / "cli" / "block.toml";

// toml++ refuses a key or a table defined twice; mpm-prep says where, as for any syntax error.
TEST(Faults, DuplicatedSceneKeyIsAnErrorWithFileAndLine) {
  const fs::path dir = temp_dir("faults_duplicate");
  std::string text = slurp(kBlock);
  const std::size_t cfl = text.find("cfl = 0.5\n");
  ASSERT_NE(cfl, std::string::npos);
  const int line = 1 + int(std::count(text.begin(), text.begin() + long(cfl), '\n'));
  std::ofstream(dir / "twice.toml") << text.substr(0, cfl) << "cfl = 0.5\ncfl = 0.4\n"
                                    << text.substr(cfl + 10);
  Result r = run("cd " + dir.string() + " && " + prep + " twice.toml -o model.mpm", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("twice.toml:" + std::to_string(line + 1) + ": TOML syntax error"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("cannot redefine existing floating-point 'cfl'"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir / "model.mpm")) << "nothing written for a refused scene";

  std::ofstream(dir / "tables.toml") << text << "\n[grid]\npadding = 1\n";
  const int tables_line = 2 + int(std::count(text.begin(), text.end(), '\n'));
  r = run("cd " + dir.string() + " && " + prep + " tables.toml -o model.mpm", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("tables.toml:" + std::to_string(tables_line) +
                       ": TOML syntax error: Error while parsing table header: cannot redefine "
                       "existing table 'grid'"),
            std::string::npos)
      << r.err;
}

// A body's mesh with a missing face: mpm-prep names the body's key, the file and the hole.
TEST(Faults, MeshWithAHoleIsRefusedSayingWhereTheHoleIs) {
  const fs::path dir = temp_dir("faults_hole");
  fs::copy_file(fs::path(MPM_TEST_DATA) / "meshes" / "open_cube.stl", dir / "lid.stl");
  std::string text = slurp(kBlock);
  const std::string from = "shape = \"box\"\nsize = \"4 4 4 mm\"";
  ASSERT_NE(text.find(from), std::string::npos);
  text.replace(text.find(from), from.size(), "shape = \"mesh\"\nfile = \"lid.stl\"\nscale = 0.004");
  std::ofstream(dir / "lid.toml") << text;
  const Result r = run("cd " + dir.string() + " && " + prep + " lid.toml -o model.mpm", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("lid.toml:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("bodies.block.file: mesh 'lid.stl' is not closed: 4 border edges around "
                       "1 hole: 4 edges around (0, 0, -0.5) in the file's coordinates"),
            std::string::npos)
      << r.err;
}

}  // namespace
}  // namespace mpm
