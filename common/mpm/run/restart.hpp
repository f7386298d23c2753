#pragma once
/// Checkpoints and restarts of mpm-run: when a checkpoint is due (CheckpointClock) and where a
/// result stream can be continued (its last intact CHKP record: scan_for_restart,
/// load_checkpoint). The time loop that writes and resumes them is run.cpp's.
#include <cstdint>
#include <string>

#include "mpm/core/state_values.hpp"
#include "mpm/scene/scene.hpp"
#include "mpm/stream/stream.hpp"

namespace mpm {

/// When the next checkpoint is due: every output.checkpoint.time of simulated time and every
/// output.checkpoint.wall of wall-clock time. A due checkpoint waits for the particles' next
/// re-sort (sort_pending() of the solver: at most kMaxWait steps) so that writing it leaves the
/// run's results bitwise unchanged.
class CheckpointClock {
 public:
  static constexpr int kMaxWait = 50;  ///< steps a due checkpoint waits for a re-sort
  /// A clock for a run at `time` (s); wall time counts from now.
  CheckpointClock(const OutputSpec& output, double time);
  /// After a step that reached `time` (s): marks a checkpoint due when one is.
  void tick(double time);
  /// Whether to write the due checkpoint now: the solver re-sorts anyway, or it waited enough.
  bool write_now(bool sort_pending);
  /// A checkpoint was written: the wall clock starts again.
  void written();
  /// The simulated time of the next one, in the checkpoint (restored on restart).
  void save(StateValues& s) const { s.set("next_checkpoint", next_time_); }
  void restore(const StateValues& s) { next_time_ = s.get("next_checkpoint"); }

 private:
  double every_time_, every_wall_;  ///< s; 0: off
  double next_time_;                ///< s of simulated time
  double last_wall_;                ///< wall time of the last checkpoint (or the start), s
  bool due_ = false;
  int waited_ = 0;  ///< steps the due checkpoint has waited
};

/// What a result stream holds for a restart.
struct RestartScan {
  std::string scene_text;       ///< its first SCEN record (the scene after overrides)
  std::size_t checkpoints = 0;  ///< intact CHKP records
  std::uint64_t keep = 0;       ///< bytes up to the end of the last of them
  std::size_t frames_kept = 0;  ///< intact frames before it
  std::uint64_t size = 0;       ///< bytes read in all
  std::string damage;           ///< where the stream was cut or corrupted; empty if clean
  bool ended = false;           ///< an ENDS record was found
  int end_status = 0;
  std::string end_message;
};

/// Reads the result stream `path` (a file) through to its end or its damage. Throws
/// StreamError for a stream that is not one, InputError for "-" and for a stream that holds no
/// scene.
RestartScan scan_for_restart(const std::string& path);

/// Checks that the scanned stream can be continued: a run that stopped without completing
/// (killed, cut, or stopped by a signal) and left a checkpoint. InputError otherwise.
void check_restartable(const std::string& path, const RestartScan& scan);

/// The last intact checkpoint of the scanned stream; with `rebar`, also the last REBR record
/// before it (the rebar's elements at the checkpoint; none: left empty).
Checkpoint load_checkpoint(const std::string& path, const RestartScan& scan,
                           Frame* rebar = nullptr);

}  // namespace mpm
