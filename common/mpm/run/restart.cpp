#include "mpm/run/restart.hpp"

#include <omp.h>

#include <tuple>

#include "mpm/core/error.hpp"

namespace mpm {

CheckpointClock::CheckpointClock(const OutputSpec& output, double time)
    : every_time_(output.checkpoint_time),
      every_wall_(output.checkpoint_wall),
      next_time_(every_time_ > 0 ? time + every_time_ : 0),
      last_wall_(omp_get_wtime()) {}

void CheckpointClock::tick(double time) {
  if (every_time_ > 0 && time >= next_time_ * (1 - 1e-12)) {
    due_ = true;
    while (next_time_ <= time * (1 + 1e-12)) next_time_ += every_time_;
  }
  if (every_wall_ > 0 && omp_get_wtime() - last_wall_ >= every_wall_) due_ = true;
}

bool CheckpointClock::write_now(bool sort_pending) {
  if (!due_) return false;
  if (sort_pending || waited_ >= kMaxWait) return true;
  ++waited_;
  return false;
}

void CheckpointClock::written() {
  due_ = false;
  waited_ = 0;
  last_wall_ = omp_get_wtime();
}

RestartScan scan_for_restart(const std::string& path) {
  if (path == "-")
    throw InputError("--restart",
                     "needs the result stream as a file (it is read twice and "
                     "continued in place), not -");
  RestartScan scan;
  StreamReader r(path);  // a bad header throws StreamError
  try {
    std::uint32_t type = 0;
    while (r.next(type)) {
      const auto t = static_cast<RecordType>(type);
      if (t == RecordType::Scene && scan.scene_text.empty()) {
        scan.scene_text = StreamReader::decode_text(r.read_payload());
      } else if (t == RecordType::End) {
        std::tie(scan.end_status, scan.end_message) = StreamReader::decode_end(r.read_payload());
        scan.ended = true;
        break;
      } else {
        r.skip();
      }
      if (t == RecordType::Checkpoint) {
        ++scan.checkpoints;
        scan.keep = r.offset();
        scan.frames_kept = r.frames_read();
      }
    }
  } catch (const StreamError& e) {
    scan.damage = e.what();
  }
  scan.size = r.offset();
  if (scan.scene_text.empty())
    throw StreamError(path, "holds no scene record: not a result stream of mpm-run");
  return scan;
}

void check_restartable(const std::string& path, const RestartScan& scan) {
  if (scan.ended && scan.end_status < 128)
    throw InputError(
        "--restart " + path,
        scan.end_status == 0
            ? "the run completed (" + scan.end_message + "); there is nothing to continue"
            : "the run ended with status " + std::to_string(scan.end_status) + " (" +
                  scan.end_message + "); continuing from its last checkpoint would repeat that");
  if (scan.checkpoints == 0)
    throw InputError("--restart " + path,
                     "holds no intact checkpoint: the run had no output.checkpoint and was not "
                     "stopped by SIGINT or SIGTERM, or it was killed before its first checkpoint" +
                         (scan.damage.empty() ? std::string() : " (" + scan.damage + ")") +
                         "; run the model again");
}

Checkpoint load_checkpoint(const std::string& path, const RestartScan& scan, Frame* rebar) {
  StreamReader r(path);
  std::size_t seen = 0;
  std::uint32_t type = 0;
  while (r.next(type)) {
    if (static_cast<RecordType>(type) == RecordType::Checkpoint && ++seen == scan.checkpoints)
      return r.read_checkpoint();
    if (rebar && static_cast<RecordType>(type) == RecordType::Rebar)
      *rebar = r.read_frame();
    else
      r.skip();
  }
  throw StreamError(path, "changed while it was read: its checkpoint " +
                              std::to_string(scan.checkpoints) + " is gone");
}

}  // namespace mpm
