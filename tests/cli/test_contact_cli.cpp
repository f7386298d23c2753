// Bad [[contact]] input: an unknown body, a negative friction coefficient, a body paired with
// itself, a rigid body, a repeated pair, and a contact scene given to the implicit solver are
// each refused with exit status 2 and a message naming the file, the line and the key.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "run_command.hpp"

namespace mpm {
namespace {

using namespace mpm::testing;
namespace fs = std::filesystem;

const fs::path kBlock = fs::path(MPM_TEST_DATA) / "cli" / "block.toml";

/// The CLI base scene with a second body, "lid", on top of the block, and `contact` appended.
fs::path two_bodies(const fs::path& dir, const std::string& name, const std::string& contact) {
  std::string text = slurp(kBlock);
  const std::string lid =
      "[[bodies]]\nname = \"lid\"\nmaterial = \"steel\"\nshape = \"box\"\n"
      "size = \"4 4 2 mm\"\ntranslate = \"0 0 5 mm\"\n\n";
  text.insert(text.find("[grid]"), lid + contact + "\n");
  const fs::path p = dir / name;
  std::ofstream(p) << text;
  return p;
}

/// Line of the first occurrence of `what` in file p, 1-based.
int line_of(const fs::path& p, const std::string& what) {
  const std::string text = slurp(p);
  return 1 + int(std::count(text.begin(), text.begin() + text.find(what), '\n'));
}

struct BadContact {
  const char* name;
  const char* table;
  const char* line_text;  // the line the message must name
  std::vector<std::string> expect;
};

TEST(ContactCli, BadContactInputExitsTwoNamingFileLineAndKey) {
  const auto dir = temp_dir("contact_cli");
  const std::vector<BadContact> cases = {
      {"unknown.toml",
       "[[contact]]\nbodies = [\"block\", \"lud\"]\n",
       "bodies = [",
       {"contact.0.bodies", "unknown body 'lud'", "block, lid"}},
      {"negative.toml",
       "[[contact]]\nbodies = [\"block\", \"lid\"]\nfriction = -0.1\n",
       "friction",
       {"contact.0.friction"}},
      {"itself.toml",
       "[[contact]]\nbodies = [\"lid\", \"lid\"]\n",
       "bodies = [",
       {"contact.0.bodies", "itself"}},
      {"one.toml", "[[contact]]\nbodies = [\"lid\"]\n", "bodies = [", {"contact.0.bodies", "two"}},
      {"normal.toml",
       "[[contact]]\nbodies = [\"block\", \"lid\"]\nnormal = \"plate\"\n",
       "normal",
       {"contact.0.normal", "'block' or 'lid'", "got 'plate'"}},
      {"gap.toml",
       "[[contact]]\nbodies = [\"block\", \"lid\"]\ngap = 0\n",
       "gap",
       {"contact.0.gap", "> 0"}},
      {"separation.toml",
       "[[contact]]\nbodies = [\"block\", \"lid\"]\nseparation = -0.1\n",
       "separation",
       {"contact.0.separation", ">= 0"}},
      {"both.toml",
       "[[contact]]\nbodies = [\"block\", \"lid\"]\ngap = 0.8\nseparation = 0.125\n",
       "separation",
       {"contact.0.separation", "not both"}},
      {"twice.toml",
       "[[contact]]\nbodies = [\"lid\", \"block\"]\n\n[[contact]]\nbodies = [\"block\", "
       "\"lid\"]\nfriction = 0.3\n",
       "bodies = [\"block\"",
       {"contact.1.bodies", "already"}},
  };
  for (const auto& c : cases) {
    const fs::path scene = two_bodies(dir, c.name, c.table);
    Result r = run(prep + " " + scene.string() + " -o /dev/null", dir);
    EXPECT_EQ(r.status, 2) << c.name << "\n" << r.err;
    const std::string at = scene.string() + ":" + std::to_string(line_of(scene, c.line_text));
    EXPECT_NE(r.err.find(at), std::string::npos) << c.name << ": " << r.err;
    for (const auto& frag : c.expect)
      EXPECT_NE(r.err.find(frag), std::string::npos) << c.name << ": " << r.err;
  }
  // A good pair passes; the implicit solver refuses it, naming the table.
  const fs::path good =
      two_bodies(dir, "good.toml", "[[contact]]\nbodies = [\"block\", \"lid\"]\n");
  EXPECT_EQ(run(prep + " " + good.string() + " -o /dev/null", dir).status, 0);
  Result r = run(prep + " " + good.string() + " --set solver.type=implicit -o /dev/null", dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("contact.0"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("explicit"), std::string::npos) << r.err;
  // A pair's keys are set by index from the command line (docs/scene.md), and they are
  // checked as in the file.
  EXPECT_EQ(run(prep + " " + good.string() +
                    " --set contact.0.friction=0.2 --set contact.0.normal=lid"
                    " --set contact.0.gap=0.8 -o /dev/null",
                dir)
                .status,
            0);
  EXPECT_EQ(run(prep + " " + good.string() + " --set contact.0.separation=0.125 -o /dev/null", dir)
                .status,
            0);
  r = run(prep + " " + good.string() + " --set contact.0.friction=-1 -o /dev/null", dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("contact.0.friction"), std::string::npos) << r.err;
  r = run(prep + " " + good.string() + " --set contact.3.friction=0.2 -o /dev/null", dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("no pair with index 3"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace mpm
