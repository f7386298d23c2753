#pragma once
/// Wall-clock time per named kernel, printed as a table at the end of a run (--stats).
#include <omp.h>

#include <string>
#include <vector>

namespace mpm {

class KernelTimers {
 public:
  /// Index of a kernel by name (created on first use). Call outside the hot loops.
  int id(const std::string& name);
  void add(int id, double seconds) {
    entries_[id].seconds += seconds;
    entries_[id].calls += 1;
  }
  struct Entry {
    std::string name;
    double seconds = 0;
    long calls = 0;
  };
  const std::vector<Entry>& entries() const { return entries_; }
  double total() const;
  /// The table: kernel, calls, seconds, share, ns per particle-step.
  std::string table(double particle_steps) const;

 private:
  std::vector<Entry> entries_;
};

/// Times a scope into a KernelTimers entry.
class ScopedTimer {
 public:
  ScopedTimer(KernelTimers& t, int id) : t_(t), id_(id), start_(omp_get_wtime()) {}
  ~ScopedTimer() { t_.add(id_, omp_get_wtime() - start_); }

 private:
  KernelTimers& t_;
  int id_;
  double start_;
};

}  // namespace mpm
