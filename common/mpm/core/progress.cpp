#include "mpm/core/progress.hpp"

#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>

namespace mpm {

namespace {
std::string clock_string(double s) {
  if (!std::isfinite(s) || s < 0) return "--:--";
  const long t = long(s + 0.5);
  char b[32];
  if (t >= 3600)
    std::snprintf(b, sizeof b, "%ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
  else
    std::snprintf(b, sizeof b, "%ld:%02ld", t / 60, t % 60);
  return b;
}
std::string time_string(double t) {
  char b[32];
  if (t < 1e-3)
    std::snprintf(b, sizeof b, "%.2f us", t * 1e6);
  else if (t < 1)
    std::snprintf(b, sizeof b, "%.3f ms", t * 1e3);
  else
    std::snprintf(b, sizeof b, "%.3f s", t);
  return b;
}
}  // namespace

Progress::Progress(ProgressMode mode, double end, double line_interval)
    : mode_(mode), end_(end), interval_(line_interval), start_(omp_get_wtime()) {
  if (mode_ == ProgressMode::Auto) mode_ = isatty(2) ? ProgressMode::Bar : ProgressMode::Lines;
  if (mode_ == ProgressMode::Bar) interval_ = 0.2;
}

void Progress::update(double t, long step) {
  if (mode_ == ProgressMode::None) return;
  const double now = omp_get_wtime();
  if (now - last_ < interval_) return;
  last_ = now;
  draw(t, step, false);
}

void Progress::done(double t, long step) {
  if (mode_ == ProgressMode::None) return;
  draw(t, step, true);
}

void Progress::draw(double t, long step, bool final) {
  const double elapsed = omp_get_wtime() - start_;
  const double f = end_ > 0 ? std::clamp(t / end_, 0.0, 1.0) : 1.0;
  const double eta = f > 0 ? elapsed * (1 - f) / f : NAN;
  if (mode_ == ProgressMode::Bar) {
    const int width = 30, filled = int(f * width + 0.5);
    std::string bar(filled, '#');
    bar += std::string(width - filled, '.');
    std::fprintf(stderr, "\r[%s] %5.1f%%  t = %s  step %ld  elapsed %s  ETA %s   ", bar.c_str(),
                 100 * f, time_string(t).c_str(), step, clock_string(elapsed).c_str(),
                 final ? "0:00" : clock_string(eta).c_str());
    if (final) std::fputc('\n', stderr);
  } else {
    std::fprintf(stderr, "mpm-run: %5.1f%%  t = %s of %s  step %ld  elapsed %s  ETA %s\n", 100 * f,
                 time_string(t).c_str(), time_string(end_).c_str(), step,
                 clock_string(elapsed).c_str(), final ? "0:00" : clock_string(eta).c_str());
  }
  std::fflush(stderr);
}

}  // namespace mpm
