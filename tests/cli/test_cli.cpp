// The command line: help, version, exit statuses, and every kind of bad input gets a clear
// message naming the file, line or key, and exit status 2 (never a crash).
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>

#include "mpm/stream/stream.hpp"
#include "run_command.hpp"

namespace mpm {
namespace {

using namespace mpm::testing;
namespace fs = std::filesystem;

const fs::path kBlock = fs::path(MPM_TEST_DATA) / "cli" / "block.toml";

/// Writes the base scene with `from` replaced by `to` (must occur) into dir/name.
fs::path variant(const fs::path& dir, const std::string& name, const std::string& from,
                 const std::string& to) {
  std::string text = slurp(kBlock);
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  const fs::path p = dir / name;
  std::ofstream(p) << text;
  return p;
}

TEST(Cli, HelpAndVersion) {
  const auto dir = temp_dir("help");
  for (const auto& tool : {prep, runner, post}) {
    Result r = run(tool + " --help", dir);
    EXPECT_EQ(r.status, 0) << tool;
    EXPECT_NE(r.out.find("Exit status"), std::string::npos) << tool << r.out;
    r = run(tool + " --version", dir);
    EXPECT_EQ(r.status, 0);
    EXPECT_TRUE(
        std::regex_search(r.out, std::regex("mpm-(prep|run|post) [0-9]+\\.[0-9]+\\.[0-9]+")))
        << r.out;
    r = run(tool + " --no-such-option", dir);
    EXPECT_EQ(r.status, 2) << tool;
  }
  for (const char* sub : {"summary", "history", "vtk", "taylor", "render"}) {
    Result r = run(post + " " + sub + " --help", dir);
    EXPECT_EQ(r.status, 0) << sub;
  }
  EXPECT_EQ(run(post, dir).status, 2);  // a subcommand is required
}

TEST(Cli, PipelineRunsAndReports) {
  const auto dir = temp_dir("pipeline");
  Result r = run(
      prep + " " + kBlock.string() + " | " + runner + " --progress none | " + post + " summary -",
      dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("frames: 5"), std::string::npos) << r.out;  // initial + 4
  EXPECT_NE(r.out.find("status 0"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("block"), std::string::npos);  // the prep summary names the body
}

struct BadScene {
  const char* name;
  const char* from;
  const char* to;
  std::vector<std::string> expect;  // fragments the message must contain
};

TEST(Cli, BadScenesAreReportedWithFileLineAndKey) {
  const auto dir = temp_dir("bad_scenes");
  const std::vector<BadScene> cases = {
      {"malformed.toml", "cfl = 0.5", "cfl = = 0.5", {"malformed.toml:", "TOML"}},
      {"unknown_key.toml", "cfl = 0.5", "cfl = 0.5\nclf = 0.4", {"unknown_key.toml:", "clf"}},
      {"unknown_nested.toml", "B = \"100 MPa\"", "B = \"100 MPa\"\nbogus = 1", {"bogus"}},
      {"unknown_material.toml", "material = \"steel\"", "material = \"stele\"", {"stele", "steel"}},
      {"negative_density.toml", "\"7800 kg/m^3\"", "\"-7800 kg/m^3\"", {"density"}},
      {"poisson.toml", "poisson_ratio = 0.3", "poisson_ratio = 0.5", {"poisson_ratio", "0.5"}},
      {"poisson2.toml", "poisson_ratio = 0.3", "poisson_ratio = 0.62", {"poisson_ratio"}},
      {"wrong_unit.toml", "\"200 GPa\"", "\"200 m/s\"", {"youngs_modulus", "velocity"}},
      {"no_particles.toml", "translate = \"0 0 2 mm\"", "translate = \"0 0 50 mm\"", {"block"}},
      {"open_mesh.toml",
       "shape = \"box\"\nsize = \"4 4 4 mm\"",
       "shape = \"mesh\"\nfile = \"open.off\"\nscale = 0.004",
       {"open.off", "closed"}},
      {"missing_mesh.toml",
       "shape = \"box\"\nsize = \"4 4 4 mm\"",
       "shape = \"mesh\"\nfile = \"nowhere.stl\"",
       {"nowhere.stl"}},
  };
  // An open mesh: a cube without its top face.
  std::ofstream(dir / "open.off")
      << "OFF\n8 5 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
         "4 0 3 2 1\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";
  for (const auto& c : cases) {
    const fs::path scene = variant(dir, c.name, c.from, c.to);
    Result r = run(prep + " " + scene.string() + " -o " + (dir / "model.mpm").string(), dir);
    EXPECT_EQ(r.status, 2) << c.name << "\n" << r.err;
    EXPECT_NE(r.err.find("error"), std::string::npos) << c.name;
    for (const auto& frag : c.expect)
      EXPECT_NE(r.err.find(frag), std::string::npos) << c.name << ": " << r.err;
    EXPECT_EQ(r.err.find("internal error"), std::string::npos) << c.name;
  }
  // A line number: the unknown key sits on a known line of the file.
  const fs::path scene = variant(dir, "line.toml", "cfl = 0.5", "cfl = 0.5\nclf = 0.4");
  std::string text = slurp(scene);
  const int line = 1 + int(std::count(text.begin(), text.begin() + text.find("clf"), '\n'));
  Result r = run(prep + " " + scene.string() + " -o /dev/null", dir);
  EXPECT_NE(r.err.find("line.toml:" + std::to_string(line)), std::string::npos) << r.err;
  // Missing scene file, bad --set.
  EXPECT_EQ(run(prep + " /no/such/scene.toml -o /dev/null", dir).status, 2);
  r = run(prep + " " + kBlock.string() + " --set solver.cfl=abc -o /dev/null", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("solver.cfl"), std::string::npos) << r.err;
  r = run(prep + " " + kBlock.string() + " --set nonsense -o /dev/null", dir);
  EXPECT_EQ(r.status, 2);
}

TEST(Cli, DamagedStreamsKeepTheFramesBefore) {
  const auto dir = temp_dir("damaged");
  const fs::path out = dir / "run.mpm";
  Result r = run(
      prep + " " + kBlock.string() + " | " + runner + " --progress none -o " + out.string(), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string bytes = slurp(out);
  ASSERT_GT(bytes.size(), 1000u);
  // Truncated in the middle of the last frame.
  {
    std::ofstream(dir / "cut.mpm", std::ios::binary) << bytes.substr(0, bytes.size() * 9 / 10);
    r = run(post + " summary " + (dir / "cut.mpm").string(), dir);
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("truncated"), std::string::npos) << r.err;
    EXPECT_NE(r.out.find("frames: 4"), std::string::npos) << r.out;  // the 4 before the cut
    r = run(post + " taylor " + (dir / "cut.mpm").string() + " --axis z --wall 0", dir);
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.out.find("L = "), std::string::npos) << "measured on the frames before";
    EXPECT_NE(r.err.find("used the 4 frame"), std::string::npos) << r.err;
  }
  // Corrupted: one byte flipped in the middle.
  {
    std::string bad = bytes;
    bad[bad.size() * 3 / 4] ^= 0x5A;
    std::ofstream(dir / "flip.mpm", std::ios::binary) << bad;
    r = run(post + " summary " + (dir / "flip.mpm").string(), dir);
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("corrupt"), std::string::npos) << r.err;
  }
  // mpm-run refuses a damaged model, a scene file and an empty input.
  r = run(prep + " " + kBlock.string() + " -o " + (dir / "model.mpm").string(), dir);
  ASSERT_EQ(r.status, 0);
  const std::string model = slurp(dir / "model.mpm");
  std::ofstream(dir / "model_cut.mpm", std::ios::binary) << model.substr(0, model.size() / 2);
  r = run(runner + " " + (dir / "model_cut.mpm").string() + " -o /dev/null", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("truncated"), std::string::npos) << r.err;
  r = run(runner + " " + kBlock.string() + " -o /dev/null", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("scene file"), std::string::npos) << r.err;
  r = run(runner + " /dev/null -o /dev/null", dir);
  EXPECT_EQ(r.status, 2);
  // Overrides of the geometry belong to mpm-prep.
  r = run(
      runner + " " + (dir / "model.mpm").string() + " --set bodies.block.velocity=1 -o /dev/null",
      dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("mpm-prep"), std::string::npos);
}

// A run that goes unstable (CFL far above 1) stops with exit status 3, names the step, the
// particle and the cause, and the frames it wrote before stay readable.
TEST(Cli, UnstableRunStopsAndKeepsItsFrames) {
  const auto dir = temp_dir("unstable");
  const fs::path out = dir / "run.mpm";
  Result r =
      run(prep + " " + kBlock.string() +
              " --set solver.cfl=6 --set output.frames=40 --set solver.end_time=\"40 us\" | " +
              runner + " --progress none -o " + out.string(),
          dir);
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("unstable at step"), std::string::npos) << r.err;
  r = run(post + " summary " + out.string(), dir);
  EXPECT_EQ(r.status, 0) << r.err;  // the stream is intact, with an end record saying why
  EXPECT_NE(r.out.find("status 3"), std::string::npos) << r.out;
  r = run(post + " history " + out.string() + " -o " + (dir / "h.csv").string(), dir);
  EXPECT_EQ(r.status, 3);  // the run's failure propagates to scripts
}

// grid.sparse: the block runs on it and lands as on the dense window (the same frames, bit
// for bit: it re-sorts at the same steps); what it cannot do is refused with the key named.
TEST(Cli, SparseGridRunsAndRefusesWhatItCannotDo) {
  const auto dir = temp_dir("sparse");
  ASSERT_EQ(run(prep + " " + kBlock.string() + " -o " + (dir / "m.mpm").string(), dir).status, 0);
  const std::string model = (dir / "m.mpm").string();
  Result r = run(runner + " " + model + " --progress none -o " + (dir / "dense.mpm").string(), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  r = run(runner + " " + model + " --progress none --set grid.sparse=true -o " +
              (dir / "sparse.mpm").string(),
          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  r = run(post + " particles " + (dir / "dense.mpm").string() + " --columns x,v,sigma", dir);
  Result q =
      run(post + " particles " + (dir / "sparse.mpm").string() + " --columns x,v,sigma", dir);
  ASSERT_EQ(r.status, 0);
  EXPECT_EQ(r.out, q.out);
  const auto refused = [&](const std::string& args, const std::string& frag) {
    Result e = run(runner + " " + model + " --progress none -o /dev/null " + args, dir);
    EXPECT_EQ(e.status, 2) << args << "\n" << e.err;
    EXPECT_NE(e.err.find(frag), std::string::npos) << args << ": " << e.err;
  };
  refused("--set grid.sparse=yes", "grid.sparse");
  refused("--set grid.sparse=true --set solver.type=implicit", "grid.sparse");
  refused("--set grid.sparse=true --strategy patch", "patch");
  const fs::path graded =
      variant(dir, "sparse_levels.toml", "[boundary]",
              "sparse = true\n\n[[grid.levels]]\nlevel = 2\nmin = \"-2 -2 0 mm\"\n"
              "max = \"2 2 4 mm\"\n\n[boundary]");
  r = run(prep + " " + graded.string() + " -o /dev/null", dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("sparse_levels.toml:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("sparse"), std::string::npos) << r.err;
}

// A scene whose step count is absurd (a density typed in the wrong unit) gets a warning from
// mpm-prep before anyone waits for the run; the base scene gets none.
TEST(Cli, PrepWarnsOfAnAbsurdStepCount) {
  const auto dir = temp_dir("steps");
  Result r = run(prep + " " + kBlock.string() + " -o " + (dir / "m.mpm").string(), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  r = run(prep + " " + kBlock.string() + " --set materials.steel.density=7.8e-12 -o " +
              (dir / "m.mpm").string(),
          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning: about"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("explicit steps"), std::string::npos) << r.err;
}

// mpm-prep says where the particles put a body's flat faces. The block's particles sit at
// (k + 1/2) 0.5 mm from the domain's corner (two a 1 mm cell), so their volumes fill whole
// 0.5 mm slabs: a face at z = 0.3 mm is filled from 0.5 mm (0.2 mm short of it), one at 4.3 mm
// to 4.5 mm (0.2 mm beyond it); faces on those planes (the base block's, its x and y faces)
// are filled exactly and not listed, nor are a sphere's or a cylinder's sides (no flat face).
TEST(Cli, PrepSaysWhereTheParticlesPutTheFaces) {
  const auto dir = temp_dir("faces");
  const std::string out = " -o " + (dir / "m.mpm").string();
  Result r = run(prep + " " + kBlock.string() + out, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("faces between"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("faces inside a cell"), std::string::npos) << r.err;  // all on node planes
  // Moved by half a cell: the particles still fill it exactly (their planes are 0.5 mm apart),
  // but its bottom and top lie midway between node planes.
  r = run(prep + " " + kBlock.string() + " --set \"bodies.block.translate=0 0 2.5 mm\"" + out, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("faces between"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("block: face z = 0.5 mm lies 0.5 mm above the node plane z = 0 mm (0.5 of "
                       "the 1 mm cells)"),
            std::string::npos)
      << r.err;
  // Its top faces nothing (the domain's top is free): not listed. With a second body above it,
  // it is (the second body's faces lie on node planes).
  EXPECT_EQ(r.err.find("block: face z = 4.5 mm lies"), std::string::npos) << r.err;
  const fs::path capped =
      variant(dir, "capped.toml", "particles_per_cell = 2\n",
              "particles_per_cell = 2\n\n[[bodies]]\nname = \"cap\"\nmaterial = \"steel\"\n"
              "shape = \"box\"\nsize = \"2 2 1 mm\"\ntranslate = \"0 0 6.5 mm\"\n");
  r = run(prep + " " + capped.string() + " --set \"bodies.block.translate=0 0 2.5 mm\"" + out, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("block: face z = 4.5 mm lies 0.5 mm above the node plane z = 4 mm (0.5 of "
                       "the 1 mm cells)"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("cap: face"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("face x"), std::string::npos) << r.err;  // the block's sides face nothing
  r = run(prep + " " + kBlock.string() + " --set \"bodies.block.translate=0 0 2.3 mm\"" + out, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("block: face z = 0.3 mm lies 0.3 mm above the node plane z = 0 mm (0.3 of "
                       "the 1 mm cells)"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("block: face z = 0.3 mm filled to 0.5 mm (0.2 mm short of it; particles "
                       "0.5 mm apart)"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("block: face z = 4.3 mm filled to 4.5 mm (0.2 mm beyond it"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("face x"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("face y"), std::string::npos) << r.err;
  // A cylinder along z from 0.3 to 3.6 mm (its ends flat: 0.5 and 3.5 mm) and a sphere.
  const fs::path two =
      variant(dir, "round.toml", "shape = \"box\"\nsize = \"4 4 4 mm\"\ntranslate = \"0 0 2 mm\"",
              "shape = \"cylinder\"\nradius = \"1.3 mm\"\nlength = \"3.3 mm\"\n"
              "translate = \"-2 -2 0.3 mm\"\n"
              "[[bodies]]\nname = \"ball\"\nmaterial = \"steel\"\n"
              "shape = \"sphere\"\nradius = \"1.3 mm\"\n"
              "translate = \"2 2 4.1 mm\"");
  r = run(prep + " " + two.string() + out, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("block: face z = 0.3 mm filled to 0.5 mm"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("block: face z = 3.6 mm filled to 3.5 mm (0.1 mm short of it"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("face x"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("face y"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("ball: face"), std::string::npos) << r.err;
}

// Nothing the user made is lost: no tool writes its output over its own input, by any name
// (a link, a relative path); the input stays byte for byte as it was, and the error is an
// input error (status 2). An -o that is a directory is an input error too, except for
// mpm-post vtk, which writes a directory and refuses an -o that is a file.
TEST(Cli, OutputOverItsOwnInputIsRefused) {
  const auto dir = temp_dir("overwrite");
  const fs::path scene = dir / "scene.toml", mesh = dir / "box.stl";
  fs::copy_file(fs::path(MPM_TEST_DATA) / "meshes" / "box_12.stl", mesh);
  {
    std::ofstream f(scene);
    f << slurp(kBlock) << "\n[[bodies]]\nname = \"meshed\"\nmaterial = \"steel\"\n"
      << "shape = \"mesh\"\nfile = \"box.stl\"\nscale = 0.001\ntranslate = \"0 0 6 mm\"\n";
  }
  const std::string scene_before = slurp(scene), mesh_before = slurp(mesh);
  const fs::path model = dir / "model.mpm", result = dir / "result.mpm";
  const std::string cd = "cd " + dir.string() + " && ";
  Result r = run(cd + prep + " scene.toml -q -o model.mpm", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  r = run(cd + runner + " --progress none model.mpm -o result.mpm", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string model_before = slurp(model), result_before = slurp(result);
  fs::create_symlink(result, dir / "link.mpm");

  const std::vector<std::string> commands = {
      prep + " scene.toml -o ./scene.toml",
      prep + " scene.toml -o box.stl",
      runner + " model.mpm -o " + model.string(),
      post + " history result.mpm -o link.mpm",
      post + " particles link.mpm -o result.mpm",
      post + " profile result.mpm --field speed --along z --bins 4 -o link.mpm",
      post + " render result.mpm -o link.mpm",
  };
  for (const auto& c : commands) {
    r = run(cd + c, dir);
    EXPECT_EQ(r.status, 2) << c << "\n" << r.err;
    EXPECT_NE(r.err.find("is the input file"), std::string::npos) << c << "\n" << r.err;
  }
  // An output that is a directory (VTK's PNG writer used to spin on one for ever).
  for (const std::string& c :
       {prep + " scene.toml -o .", runner + " model.mpm -o .", post + " history result.mpm -o .",
        post + " render result.mpm -o ."}) {
    r = run(cd + "timeout 120 " + c, dir);
    EXPECT_EQ(r.status, 2) << c << "\n" << r.err;
    EXPECT_NE(r.err.find("is a directory"), std::string::npos) << c << "\n" << r.err;
  }
  r = run(cd + post + " vtk result.mpm -o result.mpm", dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("is not a directory"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(scene), scene_before);
  EXPECT_EQ(slurp(mesh), mesh_before);
  EXPECT_EQ(slurp(model), model_before);
  EXPECT_EQ(slurp(result), result_before);
}

}  // namespace
}  // namespace mpm

namespace mpm {
namespace {

std::vector<Frame> frames_of(const std::string& path) {
  std::vector<Frame> out;
  StreamVisitor v;
  v.frame = [&](Frame&& f) { out.push_back(std::move(f)); };
  const StreamSummary s = read_stream(path, v);
  EXPECT_TRUE(s.damage.empty()) << s.damage;
  return out;
}

// The default strategy's frames are bitwise the same at 1 and 2 threads, through the tools;
// --deterministic refuses strategies that cannot promise it.
TEST(Cli, DeterministicFramesAtOneAndTwoThreads) {
  const auto dir = mpm::testing::temp_dir("deterministic");
  const std::string model = (dir / "model.mpm").string();
  using mpm::testing::run;
  ASSERT_EQ(run(mpm::testing::prep + " " +
                    (std::filesystem::path(MPM_TEST_DATA) / "cli" / "block.toml").string() +
                    " -o " + model,
                dir)
                .status,
            0);
  for (int t : {1, 2})
    ASSERT_EQ(
        run(mpm::testing::runner + " " + model + " --deterministic --threads " + std::to_string(t) +
                " --progress none -o " + (dir / ("t" + std::to_string(t) + ".mpm")).string(),
            dir)
            .status,
        0);
  const auto a = frames_of((dir / "t1.mpm").string()), b = frames_of((dir / "t2.mpm").string());
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 2u);
  for (std::size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a[k].columns.columns().size(), b[k].columns.columns().size());
    for (const auto& c : a[k].columns.columns()) {
      const Column& d = b[k].columns.at(c.info().name);
      ASSERT_EQ(c.bytes(), d.bytes());
      EXPECT_EQ(std::memcmp(c.data(), d.data(), c.bytes()), 0)
          << "frame " << k << " column " << c.info().name;
    }
  }
  const auto r = run(
      mpm::testing::runner + " " + model + " --deterministic --strategy patch -o /dev/null", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--deterministic"), std::string::npos) << r.err;
  EXPECT_EQ(run(mpm::testing::runner + " " + model + " --strategy bogus -o /dev/null", dir).status,
            2);
}

}  // namespace
}  // namespace mpm
