// mpm-run under `mpirun -np 2` (the slab decomposition of common/mpm/solver/ranks.hpp) against
// the same model run by one process, with the real binaries. The ranks hold disjoint particles
// and sum the nodes their windows share; the only difference from one process is the order of
// the sums at those nodes (and the re-sorts the ranks ask for), so every particle's state, every
// history column and the measures must agree to round-off: 1e-10 of their scale, where a
// particle's contribution missing from a shared node, or counted twice, moves results by
// 1e-3 and more. Two 2-rank runs must write the same stream, byte for byte.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>

#include "mpm/core/comm.hpp"
#include "mpm/stream/stream.hpp"
#include "run_command.hpp"

namespace mpm {
namespace {

using namespace mpm::testing;
namespace fs = std::filesystem;

constexpr double kTolerance = 1e-10;

/// mpirun for the tests: two ranks on any machine (--oversubscribe), allowed as root (CI),
/// shared-memory transport without the kernel's cross-memory attach (refused in containers).
/// Under `make test-asan` Open MPI keeps its components loaded and the ranks unwind malloc's
/// stack in full (ASan's fast unwinder stops in Open MPI's libraries, built without frame
/// pointers), so that LeakSanitizer sees Open MPI's own leaks inside Open MPI, where
/// tests/tools/lsan.supp names them; outside ASan both settings do nothing.
std::string mpirun2() {
  return "OMPI_MCA_btl_vader_single_copy_mechanism=none "
         "OMPI_MCA_mca_base_component_disable_dlclose=1 "
         "ASAN_OPTIONS=${ASAN_OPTIONS}:fast_unwind_on_malloc=0 OMP_WAIT_POLICY=passive mpirun "
         "--allow-run-as-root --oversubscribe -np 2 ";
}

struct RunOut {
  std::vector<Frame> frames;
  HistoryBlock history;  ///< all rows
  std::vector<Frame> escapes;
  int status = -1;
};

RunOut read_run(const fs::path& p) {
  RunOut r;
  StreamVisitor v;
  v.frame = [&](Frame&& f) { r.frames.push_back(std::move(f)); };
  v.escapes = [&](Frame&& f) { r.escapes.push_back(std::move(f)); };
  v.history = [&](HistoryBlock&& h) { append_history(r.history, std::move(h)); };
  const StreamSummary s = read_stream(p.string(), v);
  EXPECT_TRUE(s.damage.empty()) << s.damage;
  r.status = s.ended ? s.end_status : -1;
  return r;
}

/// Largest difference of a frame's f64 columns between two runs, by particle id, relative to
/// the column's largest magnitude; the particle counts must be equal.
double frame_difference(const Frame& a, const Frame& b, std::string& worst_column) {
  const ColumnStore &p = a.columns, &q = b.columns;
  EXPECT_EQ(p.size(), q.size());
  if (p.size() != q.size()) return INFINITY;
  std::map<std::uint32_t, std::size_t> at;
  const auto* idq = q.get<std::uint32_t>("id");
  for (std::size_t i = 0; i < q.size(); ++i) at[idq[i]] = i;
  const auto* idp = p.get<std::uint32_t>("id");
  double worst = 0;
  for (const Column& c : p.columns()) {
    if (c.info().type != ScalarType::F64) continue;
    const Column* d = q.find(c.info().name);
    EXPECT_NE(d, nullptr) << c.info().name;
    if (!d) return INFINITY;
    const int k = c.info().components;
    const auto* x = reinterpret_cast<const double*>(c.data());
    const auto* y = reinterpret_cast<const double*>(d->data());
    double scale = 0, diff = 0;
    for (std::size_t i = 0; i < p.size() * std::size_t(k); ++i)
      scale = std::max(scale, std::abs(x[i]));
    for (std::size_t i = 0; i < p.size(); ++i) {
      const auto j = at.find(idp[i]);
      if (j == at.end()) return INFINITY;
      for (int m = 0; m < k; ++m)
        diff = std::max(diff, std::abs(x[i * std::size_t(k) + std::size_t(m)] -
                                       y[j->second * std::size_t(k) + std::size_t(m)]));
    }
    const double rel = scale > 0 ? diff / scale : diff;
    if (rel > worst) worst = rel, worst_column = c.info().name;
  }
  return worst;
}

/// The name of a vector's components' group: "force_platen_y" -> "force_platen", else itself.
std::string group_of(const std::string& name) {
  const std::size_t n = name.size();
  if (n > 2 && name[n - 2] == '_' &&
      (name[n - 1] == 'x' || name[n - 1] == 'y' || name[n - 1] == 'z'))
    return name.substr(0, n - 2);
  return name;
}

/// Largest difference of the history columns, relative to each column's largest magnitude,
/// a vector's components to the largest of its components (a component that stays zero holds
/// round-off only).
double history_difference(const HistoryBlock& a, const HistoryBlock& b, std::string& worst_column) {
  EXPECT_EQ(a.names, b.names);
  EXPECT_EQ(a.rows(), b.rows());
  if (a.names != b.names || a.rows() != b.rows()) return INFINITY;
  const std::size_t nc = a.names.size();
  std::map<std::string, double> scale;
  for (std::size_t c = 0; c < nc; ++c)
    for (std::size_t r = 0; r < a.rows(); ++r) {
      double& s = scale[group_of(a.names[c])];
      s = std::max(s, std::abs(a.values[r * nc + c]));
    }
  double worst = 0;
  for (std::size_t c = 0; c < nc; ++c) {
    double diff = 0;
    for (std::size_t r = 0; r < a.rows(); ++r)
      diff = std::max(diff, std::abs(a.values[r * nc + c] - b.values[r * nc + c]));
    const double s = scale[group_of(a.names[c])];
    const double rel = s > 0 ? diff / s : diff;
    if (rel > worst) worst = rel, worst_column = a.names[c];
  }
  return worst;
}

/// The model of `scene` (mpm-prep with `sets`), run by one process and twice by two ranks, one
/// thread each; returns the directory. Checks the runs against each other.
fs::path check_ranks(const std::string& name, const std::string& scene, const std::string& sets) {
  const fs::path dir = temp_dir("mpi_" + name), model = dir / "model.mpm";
  EXPECT_EQ(run(prep + " " + scene + " " + sets + " -o " + model.string(), dir).status, 0);
  const std::string args = model.string() + " --threads 1 --progress none -o ";
  const Result one =
      run("OMP_WAIT_POLICY=passive " + runner + " " + args + (dir / "one.mpm").string(), dir);
  EXPECT_EQ(one.status, 0) << one.err;
  for (int k = 0; k < 2; ++k) {
    const Result two =
        run(mpirun2() + runner + " " + args + (dir / ("two" + std::to_string(k) + ".mpm")).string(),
            dir);
    EXPECT_EQ(two.status, 0) << two.err;
  }
  const RunOut a = read_run(dir / "one.mpm"), b = read_run(dir / "two0.mpm");
  EXPECT_EQ(a.status, 0);
  EXPECT_EQ(b.status, 0);
  EXPECT_EQ(a.frames.size(), b.frames.size());
  double frames_worst = 0;
  for (std::size_t f = 0; f < std::min(a.frames.size(), b.frames.size()); ++f) {
    std::string column;
    EXPECT_EQ(a.frames[f].step, b.frames[f].step) << name << " frame " << f;
    const double d = frame_difference(a.frames[f], b.frames[f], column);
    EXPECT_LE(d, kTolerance) << name << " frame " << f << ", column " << column;
    frames_worst = std::max(frames_worst, d);
  }
  std::string column;
  const double h = history_difference(a.history, b.history, column);
  EXPECT_LE(h, kTolerance) << name << " history column " << column;
  std::printf(
      "%s: %zu frames of %zu particles; 2 ranks against 1 process: frames %.3g, "
      "history %.3g (%s) of their scale\n",
      name.c_str(), a.frames.size(), a.frames.empty() ? 0 : a.frames.back().columns.size(),
      frames_worst, h, column.c_str());
  // What left the domain: the same particles (ESCP records gathered from the ranks).
  std::size_t ea = 0, eb = 0;
  for (const Frame& e : a.escapes) ea += e.columns.size();
  for (const Frame& e : b.escapes) eb += e.columns.size();
  EXPECT_EQ(ea, eb) << name;
  // Two 2-rank runs: the same stream, byte for byte.
  EXPECT_EQ(slurp(dir / "two0.mpm"), slurp(dir / "two1.mpm")) << name << ": 2-rank runs differ";
  return dir;
}

bool have_mpi() {
  return comm_has_mpi() && run("command -v mpirun", fs::temp_directory_path()).status == 0;
}

const std::string kData = std::string(MPM_TEST_DATA) + "/cli/";
const std::string kExamples = std::string(MPM_EXAMPLES) + "/";

// The Taylor bar of V2 (0.76 mm cells, 21 172 particles, 80 us): the slabs cut along the bar,
// the wall's force counted once; L and D equal to 1e-10.
TEST(Mpi, TaylorBarTwoRanksMatchOneProcess) {
  if (!have_mpi()) GTEST_SKIP() << "built without MPI (MPM_MPI off) or no mpirun";
  const fs::path dir = check_ranks("taylor", kExamples + "taylor-bar/scene.toml", "");
  const Result a = run(post + " taylor --json " + (dir / "one.mpm").string(), dir);
  const Result b = run(post + " taylor --json " + (dir / "two0.mpm").string(), dir);
  for (const char* key : {"L", "D"}) {
    const double x = json_value(a.out, key), y = json_value(b.out, key);
    EXPECT_LE(std::abs(x - y), kTolerance * std::abs(x)) << key << ": " << x << " against " << y;
  }
  // The pipeline: the model on mpirun's standard input, the stream on its standard output (a
  // rank's is mpirun's pseudo-terminal): the same bytes as the run that wrote a file.
  const Result p = run(prep + " " + kExamples + "taylor-bar/scene.toml | " + mpirun2() + runner +
                           " --threads 1 --progress none | cat > " + (dir / "pipe.mpm").string(),
                       dir);
  EXPECT_EQ(p.status, 0) << p.err;
  EXPECT_EQ(slurp(dir / "pipe.mpm"), slurp(dir / "two0.mpm")) << "mpirun in a pipe";
}

// The sparse grid (its shared nodes are the active ones both ranks have).
TEST(Mpi, SparseGridTwoRanksMatchOneProcess) {
  if (!have_mpi()) GTEST_SKIP() << "built without MPI (MPM_MPI off) or no mpirun";
  check_ranks("sparse", kData + "taylor_restart.toml", "--set grid.sparse=true");
}

// Particles that leave the domain on either rank: removed, booked and logged on every rank.
TEST(Mpi, EscapingParticlesTwoRanksMatchOneProcess) {
  if (!have_mpi()) GTEST_SKIP() << "built without MPI (MPM_MPI off) or no mpirun";
  check_ranks("escape", kData + "escape.toml", "");
}

// A rigid platen across the cut: its marks on the shared nodes, its force and its work (the
// history's force_platen_z and external_work) equal to one process's.
TEST(Mpi, RigidPlatenAcrossTheCutMatchesOneProcess) {
  if (!have_mpi()) GTEST_SKIP() << "built without MPI (MPM_MPI off) or no mpirun";
  check_ranks("platen", kData + "platen.toml", "");
}

// HJC concrete with its damage averaged over 6 mm (damage_length): the damaging particles'
// lattice box agreed between the ranks and the lattice's sums added across them, so each
// particle's damage is one process's to round-off.
TEST(Mpi, AveragedDamageAcrossTheCutMatchesOneProcess) {
  if (!have_mpi()) GTEST_SKIP() << "built without MPI (MPM_MPI off) or no mpirun";
  check_ranks("hjc_nonlocal", kData + "hjc_nonlocal.toml", "");
}

// A particle that leaves the domain with solver.on_exit = "stop" stops every rank: exit 5, the
// stream ended by the root with that status and the frames before it intact, as one process.
TEST(Mpi, ParticleLeavingTheDomainStopsEveryRank) {
  if (!have_mpi()) GTEST_SKIP() << "built without MPI (MPM_MPI off) or no mpirun";
  const fs::path dir = temp_dir("mpi_stop"), model = dir / "model.mpm";
  ASSERT_EQ(
      run(prep + " " + kData + "escape.toml --set solver.on_exit=stop -o " + model.string(), dir)
          .status,
      0);
  const std::string args = model.string() + " --threads 1 --progress none -o ";
  const Result one = run(runner + " " + args + (dir / "one.mpm").string(), dir);
  const Result two = run(mpirun2() + runner + " " + args + (dir / "two.mpm").string(), dir);
  EXPECT_EQ(one.status, 5) << one.err;
  EXPECT_EQ(two.status, 5) << two.err;
  EXPECT_NE(two.err.find("left the domain"), std::string::npos) << two.err;
  const RunOut a = read_run(dir / "one.mpm"), b = read_run(dir / "two.mpm");
  EXPECT_EQ(a.status, 5);
  EXPECT_EQ(b.status, 5);
  EXPECT_EQ(a.frames.size(), b.frames.size());
  EXPECT_EQ(a.history.rows(), b.history.rows());
}

// What the decomposition does not cover (here B-spline shape functions) is refused on every
// rank with exit 2 and one message.
TEST(Mpi, RefusesWhatItDoesNotDecompose) {
  if (!have_mpi()) GTEST_SKIP() << "built without MPI (MPM_MPI off) or no mpirun";
  const fs::path dir = temp_dir("mpi_refuse"), model = dir / "model.mpm";
  ASSERT_EQ(run(prep + " " + kExamples + "taylor-bar/scene.toml -o " + model.string(), dir).status,
            0);
  const Result r =
      run(mpirun2() + runner + " " + model.string() +
              " --set grid.shape=bspline --progress none -o " + (dir / "out.mpm").string(),
          dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("runs on one process; under mpirun (2 ranks)"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace mpm
