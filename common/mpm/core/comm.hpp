#pragma once
/// The processes of a run (MPI ranks) and what they say to each other. Built with MPI (the
/// build option MPM_MPI, on when CMake finds MPI) the world is MPI_COMM_WORLD of the processes
/// `mpirun` started; without MPI, or when mpm-run is started alone, it is one process and every
/// call is a copy or nothing. Every collective here gives the same bits on every rank and in
/// every run: sums are taken in rank order, never by MPI's reduction trees.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace mpm {

class Comm {
 public:
  /// The processes of this run (one until a CommSession started MPI).
  static Comm& world();

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool root() const { return rank_ == 0; }
  bool parallel() const { return size_ > 1; }

  /// v[0, n) summed over the ranks in rank order: the same bits on every rank.
  void sum(double* v, int n) const;
  double sum(double v) const {
    sum(&v, 1);
    return v;
  }
  double min(double v) const;
  double max(double v) const;
  /// True on every rank when it is true on any.
  bool any(bool v) const { return max(v ? 1.0 : 0.0) > 0; }
  /// Every rank's bytes, in rank order, on every rank.
  std::vector<std::string> all_gather(const std::string& mine) const;
  /// Every rank's bytes at the root, one after the other in rank order, rank r's from
  /// offsets[r] to offsets[r + 1] (size() + 1 offsets); empty elsewhere.
  std::string gather(const std::string& mine, std::vector<std::size_t>& offsets) const;
  /// The root's bytes on every rank.
  void broadcast(std::string& bytes) const;
  /// Sends send[r] to rank r (send has size() entries; its own is kept) and returns what each
  /// rank sent to this one, in rank order.
  std::vector<std::string> all_to_all(std::vector<std::string> send) const;
  /// Exchanges buffers with some ranks: send[k] goes to partners[k] and recv[k] (sized by the
  /// caller to what partners[k] sends) is filled from it. Partners must name each other.
  void exchange(const std::vector<int>& partners, const std::vector<std::vector<double>>& send,
                std::vector<std::vector<double>>& recv) const;
  /// Ends every process of the run with `status` (a rank that cannot go on alone).
  [[noreturn]] void abort(int status) const;

  /// Bytes and messages this rank sent since the start (for the cost of the decomposition).
  double bytes_sent() const { return bytes_; }
  double messages_sent() const { return messages_; }

 private:
  friend class CommSession;
  int rank_ = 0, size_ = 1;
  bool mpi_ = false;
  mutable double bytes_ = 0, messages_ = 0;
};

/// Starts MPI for the life of the object when the program was built with it and was started by
/// mpirun (or always, with MPI: a singleton run is a world of one); ends it after.
class CommSession {
 public:
  CommSession(int& argc, char**& argv);
  ~CommSession();
  CommSession(const CommSession&) = delete;
  CommSession& operator=(const CommSession&) = delete;
};

/// True when this build can run under mpirun.
bool comm_has_mpi();

}  // namespace mpm
