// Checkpoint and restart, and the faults a run meets: a run killed with SIGKILL, or its
// stream cut at every record boundary and at random bytes, continues with mpm-run --restart
// into a file byte for byte the uninterrupted run's; SIGTERM stops a run after a checkpoint
// with exit 143; a full disk and a reader that goes away give exit 4 and a stream that no
// reader takes for whole. Base case: a small Taylor bar (tests/data/cli/taylor_restart.toml,
// about 1 000 particles, 108 steps, a checkpoint every 1.5 us). One thread: on a loaded machine
// two spinning OpenMP threads make these many short runs slow.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>

#include "mpm/stream/stream.hpp"
#include "run_command.hpp"

namespace mpm {
namespace {

using namespace mpm::testing;
namespace fs = std::filesystem;

const fs::path kBar = fs::path(MPM_TEST_DATA) / "cli" / "taylor_restart.toml";
const fs::path kBlock = fs::path(MPM_TEST_DATA) / "cli" / "block.toml";

struct RecordSpan {
  std::uint32_t type;
  std::uint64_t begin, end;  ///< bytes [begin, end) of the stream
};

/// The records of an intact stream, in order.
std::vector<RecordSpan> records_of(const fs::path& p) {
  std::vector<RecordSpan> out;
  StreamReader r(p.string());
  std::uint32_t type = 0;
  while (r.next(type)) {
    const std::uint64_t begin = r.record_offset();
    r.skip();
    out.push_back({type, begin, r.offset()});
  }
  return out;
}

/// The FRAM records of an intact stream, as bytes.
std::vector<std::string> frames_of(const fs::path& p) {
  std::vector<std::string> out;
  const std::string b = slurp(p);
  for (const RecordSpan& s : records_of(p))
    if (s.type == std::uint32_t(RecordType::Frame))
      out.push_back(b.substr(s.begin, s.end - s.begin));
  return out;
}

/// The model of the bar and its uninterrupted run with checkpoints, made once per test.
struct Bar {
  fs::path dir, model, full;
  std::string bytes;
  std::vector<RecordSpan> records;
  std::uint64_t first_checkpoint_end = 0;
  /// `end_time`: the scene's 6 us, or longer (a run that a signal must reach mid-run).
  explicit Bar(const std::string& name, const std::string& end_time = "6 us")
      : dir(temp_dir(name)) {
    model = dir / "model.mpm";
    full = dir / "full.mpm";
    std::string scene = slurp(kBar);
    scene.replace(scene.find("end_time = \"6 us\""), 17, "end_time = \"" + end_time + "\"");
    std::ofstream(dir / "bar.toml") << scene;
    EXPECT_EQ(run(prep + " " + (dir / "bar.toml").string() + " -o " + model.string(), dir).status,
              0);
    const Result r = run(
        runner + " " + model.string() + " --threads 1 --progress none -o " + full.string(), dir);
    EXPECT_EQ(r.status, 0) << r.err;
    bytes = slurp(full);
    records = records_of(full);
    for (const RecordSpan& s : records)
      if (s.type == std::uint32_t(RecordType::Checkpoint) && first_checkpoint_end == 0)
        first_checkpoint_end = s.end;
  }
  /// `mpm-run --restart` on the first `n` bytes of the uninterrupted run, in place.
  Result restart_cut(std::uint64_t n, const std::string& name) const {
    const fs::path cut = dir / name;
    std::ofstream(cut, std::ios::binary) << bytes.substr(0, n);
    return run(runner + " --restart " + cut.string() + " --threads 1 --progress none", dir);
  }
};

// Checkpoints wait for the particles' own re-sort, so a run that writes them gives bitwise
// the frames of the run without them.
TEST(Restart, CheckpointsLeaveTheFramesBitwiseUnchanged) {
  const Bar bar("restart_unchanged");
  std::string scene = slurp(kBar);
  scene.replace(scene.find("checkpoint = "), 10, "# checkpoi");
  std::ofstream(bar.dir / "plain.toml") << scene;
  const fs::path plain = bar.dir / "plain.mpm";
  ASSERT_EQ(prep_and_run(bar.dir / "plain.toml", "", plain, bar.dir).status, 0);
  const auto a = frames_of(bar.full), b = frames_of(plain);
  ASSERT_EQ(a.size(), 5u);  // the initial state and 4 frames
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) EXPECT_TRUE(a[k] == b[k]) << "frame " << k;
  std::size_t checkpoints = 0;
  for (const RecordSpan& s : bar.records)
    checkpoints += s.type == std::uint32_t(RecordType::Checkpoint);
  EXPECT_EQ(checkpoints, 3u);  // at 1.5, 3 and 4.5 us, none at the end
}

// A stream cut at every record boundary after the first checkpoint and at random bytes
// continues into the uninterrupted run's file, byte for byte; cut before it, it is refused.
TEST(Restart, StreamCutAnywhereContinuesBitwise) {
  const Bar bar("restart_cuts");
  ASSERT_GT(bar.first_checkpoint_end, 0u);
  std::vector<std::uint64_t> cuts;
  for (const RecordSpan& s : bar.records)
    if (s.end >= bar.first_checkpoint_end && s.end < bar.bytes.size()) cuts.push_back(s.end);
  std::mt19937_64 rng(21);
  std::uniform_int_distribution<std::uint64_t> any(bar.first_checkpoint_end, bar.bytes.size() - 1);
  for (int k = 0; k < 4; ++k) cuts.push_back(any(rng));
  for (std::uint64_t n : cuts) {
    const Result r = bar.restart_cut(n, "cut.mpm");
    ASSERT_EQ(r.status, 0) << "cut at byte " << n << ": " << r.err;
    EXPECT_NE(r.err.find("continuing"), std::string::npos) << r.err;
    EXPECT_TRUE(slurp(bar.dir / "cut.mpm") == bar.bytes) << "cut at byte " << n;
  }
  // Before the first checkpoint: nothing to continue from (exit 2, saying so).
  const Result r = bar.restart_cut(bar.first_checkpoint_end - 5, "early.mpm");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no intact checkpoint"), std::string::npos) << r.err;
}

/// A scene run to the end with checkpoints (the model made by `prep_args`), then continued from
/// its stream cut at every record boundary after the first checkpoint and at `random` random
/// bytes after it: each continued file must be the uninterrupted one, byte for byte. Returns
/// the uninterrupted run's records.
std::vector<RecordSpan> expect_every_cut_continues(const std::string& name,
                                                   const std::string& prep_args, int random) {
  const fs::path dir = temp_dir(name);
  const fs::path model = dir / "model.mpm", full = dir / "full.mpm";
  EXPECT_EQ(run(prep + " " + prep_args + " -o " + model.string(), dir).status, 0);
  const Result r0 =
      run(runner + " " + model.string() + " --threads 1 --progress none -o " + full.string(), dir);
  EXPECT_EQ(r0.status, 0) << r0.err;
  const std::string bytes = slurp(full);
  const std::vector<RecordSpan> records = records_of(full);
  std::uint64_t first = 0;
  std::vector<std::uint64_t> cuts;
  for (const RecordSpan& s : records) {
    if (s.type == std::uint32_t(RecordType::Checkpoint) && first == 0) first = s.end;
    if (first && s.end < bytes.size()) cuts.push_back(s.end);
  }
  EXPECT_GT(first, 0u) << "no checkpoint";
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<std::uint64_t> any(first, bytes.size() - 1);
  for (int k = 0; first && k < random; ++k) cuts.push_back(any(rng));
  for (std::uint64_t n : cuts) {
    const fs::path cut = dir / "cut.mpm";
    std::ofstream(cut, std::ios::binary) << bytes.substr(0, n);
    const Result r =
        run(runner + " --restart " + cut.string() + " --threads 1 --progress none", dir);
    EXPECT_EQ(r.status, 0) << "cut at byte " << n << ": " << r.err;
    EXPECT_TRUE(slurp(cut) == bytes) << "cut at byte " << n;
  }
  return records;
}

int count(const std::vector<RecordSpan>& records, RecordType type) {
  int n = 0;
  for (const RecordSpan& s : records) n += s.type == std::uint32_t(type);
  return n;
}

// A graded grid whose level-2 box follows a disk across the domain (the window and the box
// move, particles split as the box reaches them): cut at every record boundary after the first
// checkpoint and at random bytes, the run continues into the uninterrupted run's file, byte
// for byte, GRID records included.
TEST(Restart, GradedGridsContinueBitwise) {
  const fs::path scene = fs::path(MPM_TEST_DATA) / "cli" / "graded_restart.toml";
  const auto records = expect_every_cut_continues("restart_graded", scene.string(), 3);
  EXPECT_EQ(count(records, RecordType::Checkpoint), 3);  // at 2, 4 and 6 us
  EXPECT_GE(count(records, RecordType::Grid), 3) << "the box must move between frames";
}

// -o writes the continued run to another file and leaves the cut one as it was.
TEST(Restart, RestartToAnotherFileKeepsTheCutOne) {
  const Bar bar("restart_other");
  const std::uint64_t n = (bar.first_checkpoint_end + bar.bytes.size()) / 2;
  const fs::path cut = bar.dir / "cut.mpm", other = bar.dir / "other.mpm";
  std::ofstream(cut, std::ios::binary) << bar.bytes.substr(0, n);
  const Result r = run(runner + " --restart " + cut.string() + " -o " + other.string() +
                           " --progress none --threads 2",
                       bar.dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(fs::file_size(cut), n);
  EXPECT_TRUE(slurp(other) == bar.bytes) << "continued at 2 threads, bitwise the 1-thread run";
}

/// Starts `runner model -o out` in the background, waits until `out` holds `bytes`, sends
/// `signal`, and prints the runner's exit status ("status N"), with bash.
std::string run_and_signal(const fs::path& model, const fs::path& out, std::uint64_t bytes,
                           const std::string& signal) {
  return runner + " " + model.string() + " --threads 1 --progress none -o " + out.string() +
         " & pid=$!; while [ $(stat -c %s " + out.string() + " 2>/dev/null || echo 0) -lt " +
         std::to_string(bytes) + " ]; do sleep 0.005; done; kill -" + signal +
         " $pid; wait $pid; echo status $?";
}

// SIGKILL mid-run, then --restart: bitwise the uninterrupted run. The run writes into a FIFO
// whose reader keeps the first bytes and then stops reading, so the kill surely comes while
// the run is blocked in the middle of a record.
TEST(Restart, KilledWithSigkillContinuesBitwise) {
  const Bar bar("restart_sigkill");
  const fs::path fifo = bar.dir / "fifo", out = bar.dir / "killed.mpm";
  const std::uint64_t n = bar.first_checkpoint_end + 1000;
  Result r = run("mkfifo " + fifo.string() + "; " + runner + " " + bar.model.string() +
                     " --threads 1 --progress none -o " + fifo.string() + " & pid=$!; { head -c " +
                     std::to_string(n) + " >" + out.string() + "; exec sleep 60; } <" +
                     fifo.string() + " & reader=$!; while [ $(stat -c %s " + out.string() +
                     " 2>/dev/null || echo 0) -lt " + std::to_string(n) +
                     " ]; do sleep 0.01; done; kill -KILL $pid; wait $pid; echo status $?; "
                     "kill $reader",
                 bar.dir);
  ASSERT_NE(r.out.find("status 137"), std::string::npos) << r.out << r.err;
  ASSERT_EQ(fs::file_size(out), n);
  r = run(runner + " --restart " + out.string() + " --threads 1 --progress none", bar.dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(slurp(out) == bar.bytes);
}

// SIGTERM: the run finishes its step, writes a checkpoint and a last frame, exits 143 saying
// how to continue; the continued run has bitwise the frames and history rows of the
// uninterrupted one (the file differs by the extra checkpoint and where HIST blocks break),
// when the particles came due for their re-sort within the 20 steps the run waits for it. On a
// loaded machine the signal can land late, on the bar come to rest, which re-sorts seldom: the
// checkpoint then re-sorts it, says so, and the continued run differs at round-off: every
// history column within 1e-9 of the largest value of its unit (the momentum along x is
// round-off about zero: its scale is the momentum along z; round-off grown over some 1000
// steps is below 1e-12 of it; a lost state value or a wrong clock shows at 1e-3 and more).
TEST(Restart, SigtermStopsAfterACheckpointAndContinues) {
  // Ten times the steps: the signal, sent when the first frame is on disk (polled every 5 ms),
  // must find the run still going on a loaded machine (the 6 us run takes some 50 ms).
  const Bar bar("restart_sigterm", "60 us");
  const fs::path out = bar.dir / "stopped.mpm";
  const std::uint64_t first_frame = bar.records[3].end;  // SCEN, INFO, HIST, FRAM
  Result r = run(run_and_signal(bar.model, out, first_frame, "TERM"), bar.dir);
  ASSERT_NE(r.out.find("status 143"), std::string::npos) << r.out << r.err;
  EXPECT_NE(r.err.find("mpm-run --restart " + out.string()), std::string::npos) << r.err;
  const bool resorted = r.err.find("so the checkpoint re-sorted them") != std::string::npos;
  RecordProperty("resorted_at_checkpoint", resorted ? "yes" : "no");  // which check ran
  r = run(post + " summary " + out.string(), bar.dir);
  EXPECT_NE(r.out.find("status 143"), std::string::npos) << r.out;
  r = run(runner + " --restart " + out.string() + " --threads 1 --progress none", bar.dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("stopped: interrupted by signal 15"), std::string::npos) << r.err;
  const auto a = frames_of(bar.full), b = frames_of(out);
  ASSERT_EQ(a.size(), b.size());
  const Result ha = run(post + " history --digits 17 " + bar.full.string(), bar.dir);
  const Result hb = run(post + " history --digits 17 " + out.string(), bar.dir);
  ASSERT_EQ(hb.status, 0) << hb.err;
  EXPECT_GT(ha.out.size(), 1000u);
  if (!resorted) {
    for (std::size_t k = 0; k < a.size(); ++k) EXPECT_TRUE(a[k] == b[k]) << "frame " << k;
    EXPECT_TRUE(ha.out == hb.out) << "history rows";
    return;
  }
  const HistoryBlock ra = history_of(bar.full), rb = history_of(out);
  ASSERT_EQ(ra.names, rb.names);
  ASSERT_EQ(ra.rows(), rb.rows());
  ASSERT_GT(ra.rows(), 100u);
  const std::size_t nc = ra.names.size();
  std::map<std::string, double> scale;  // by unit
  for (std::size_t r = 0; r < ra.rows(); ++r)
    for (std::size_t c = 0; c < nc; ++c)
      scale[ra.units[c]] = std::max(scale[ra.units[c]], std::abs(ra.values[r * nc + c]));
  for (std::size_t c = 0; c < nc; ++c) {
    double worst = 0;
    for (std::size_t r = 0; r < ra.rows(); ++r)
      worst = std::max(worst, std::abs(ra.values[r * nc + c] - rb.values[r * nc + c]));
    EXPECT_LE(worst, 1e-9 * scale[ra.units[c]]) << "history column " << ra.names[c] << " ("
                                                << ra.units[c] << "; re-sorted at the checkpoint)";
  }
}

// What cannot be continued is refused with exit 2 and a reason.
TEST(Restart, RefusesWhatItCannotContinue) {
  const Bar bar("restart_refused");
  const std::string full = bar.full.string();
  Result r = run(runner + " --restart " + full, bar.dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("the run completed"), std::string::npos) << r.err;
  EXPECT_EQ(fs::file_size(bar.full), bar.bytes.size()) << "left untouched";
  r = run(runner + " --restart -", bar.dir);
  EXPECT_EQ(r.status, 2);
  r = run(runner + " --restart " + full + " --set solver.cfl=0.3", bar.dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--set"), std::string::npos) << r.err;
  r = run(runner + " " + bar.model.string() + " --restart " + full, bar.dir);
  EXPECT_EQ(r.status, 2);
  r = run(runner + " --restart " + bar.model.string(), bar.dir);  // a model, not a result
  EXPECT_EQ(r.status, 2);
}

// The implicit solver (the block of tests/data/cli/block.toml, warm start from the previous
// step): cut at every record boundary after the first checkpoint, the run continues into the
// uninterrupted run's file byte for byte (a checkpoint drops the warm start in both runs,
// docs/format.md).
TEST(Restart, ImplicitRunsContinueBitwise) {
  const auto records = expect_every_cut_continues(
      "restart_implicit",
      kBlock.string() +
          " --set solver.type=implicit --set solver.implicit.initial_guess=previous"
          " --set output.checkpoint.time=1us",
      0);
  EXPECT_EQ(count(records, RecordType::Checkpoint), 3);  // at 1, 2 and 3 us: written at once
}

// A full disk: exit 4 with the system's message. With a file-size limit the disk fills in the
// middle of a record: the stream then reads as truncated (exit 2), never as a complete run,
// and the run continues from its last checkpoint.
TEST(Faults, FullDiskStopsWithExit4AndACutStream) {
  const Bar bar("fault_full");
  Result r =
      run(runner + " " + bar.model.string() + " --threads 1 --progress none -o /dev/full", bar.dir);
  EXPECT_EQ(r.status, 4);
  EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
  r = run(prep + " " + kBar.string() + " -o /dev/full", bar.dir);
  EXPECT_EQ(r.status, 4);
  const fs::path out = bar.dir / "limited.mpm";
  const std::uint64_t limit_kb = (bar.first_checkpoint_end + bar.bytes.size()) / 2 / 1024;
  r = run("ulimit -f " + std::to_string(limit_kb) + "; trap \"\" XFSZ; " + runner + " " +
              bar.model.string() + " --threads 1 --progress none -o " + out.string(),
          bar.dir);
  EXPECT_EQ(r.status, 4);
  EXPECT_NE(r.err.find("write failed"), std::string::npos) << r.err;
  EXPECT_LE(fs::file_size(out), limit_kb * 1024);
  r = run(post + " summary " + out.string(), bar.dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("truncated"), std::string::npos) << r.err;
  r = run(runner + " --restart " + out.string() + " --threads 1 --progress none", bar.dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(slurp(out) == bar.bytes);
}

// The reader of the pipe goes away after 1000 bytes: mpm-run stops with exit 4 (Broken pipe)
// instead of hanging or dying of SIGPIPE.
TEST(Faults, ReaderThatGoesAwayGivesExit4) {
  const auto dir = temp_dir("fault_pipe");
  Result r = run(prep + " " + kBar.string() + " -o " + (dir / "model.mpm").string(), dir);
  ASSERT_EQ(r.status, 0);
  r = run(
      "timeout 300 " + runner + " " + (dir / "model.mpm").string() +
          " --threads 1 --progress none | head -c 1000 >/dev/null; echo statuses ${PIPESTATUS[@]}",
      dir);
  EXPECT_NE(r.out.find("statuses 4 0"), std::string::npos) << r.out << r.err;
  EXPECT_NE(r.err.find("Broken pipe"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace mpm
