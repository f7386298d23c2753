#pragma once
/// Progress on stderr: a bar with ETA on a terminal, a line every few seconds otherwise.
#include <cstdio>
#include <string>

namespace mpm {

enum class ProgressMode { Auto, Bar, Lines, None };

class Progress {
 public:
  /// `end` is the simulated end time (s); `line_interval` the wall seconds between lines.
  Progress(ProgressMode mode, double end, double line_interval = 5.0);
  /// Reports the simulated time t (s) reached after `step` steps.
  void update(double t, long step);
  /// Clears the bar (call before printing anything else to stderr) and prints a final line.
  void done(double t, long step);

 private:
  void draw(double t, long step, bool final);
  ProgressMode mode_;
  double end_, interval_, start_, last_ = -1e30;
};

}  // namespace mpm
