#include "mpm/core/comm.hpp"

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <stdexcept>

#ifdef MPM_HAVE_MPI
// The C interface only (no deprecated C++ bindings to link).
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#endif

namespace mpm {

Comm& Comm::world() {
  static Comm w;
  return w;
}

bool comm_has_mpi() {
#ifdef MPM_HAVE_MPI
  return true;
#else
  return false;
#endif
}

#ifdef MPM_HAVE_MPI

namespace {

/// Started by mpirun (Open MPI, or a PMI launcher such as MPICH's hydra or Slurm's srun).
bool launched_by_mpirun() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"})
    if (std::getenv(v)) return true;
  return false;
}

void check(int err, const char* what) {
  if (err != MPI_SUCCESS) throw std::runtime_error(std::string("MPI: ") + what + " failed");
}

int count_of(std::size_t n) {
  if (n > std::size_t(std::numeric_limits<int>::max()))
    throw std::runtime_error("MPI: a message of " + std::to_string(n) + " bytes exceeds 2^31");
  return int(n);
}

/// displs[r] = the bytes before rank r's (counts in rank order); returns the total.
std::size_t displacements(const std::vector<int>& counts, std::vector<int>& displs) {
  std::size_t total = 0;
  displs.resize(counts.size());
  for (std::size_t r = 0; r < counts.size(); ++r)
    displs[r] = count_of(total), total += std::size_t(counts[r]);
  return total;
}

}  // namespace

CommSession::CommSession(int& argc, char**& argv) {
  if (!launched_by_mpirun()) return;
  int provided = 0;
  // Only the main thread calls MPI (outside the OpenMP regions).
  check(MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
  Comm& w = Comm::world();
  w.mpi_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &w.rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &w.size_);
}

CommSession::~CommSession() {
  Comm& w = Comm::world();
  if (!w.mpi_) return;
  MPI_Finalize();
  w.mpi_ = false;
}

void Comm::sum(double* v, int n) const {
  if (size_ == 1 || n == 0) return;
  std::vector<double> all(std::size_t(n) * std::size_t(size_));
  check(MPI_Allgather(v, n, MPI_DOUBLE, all.data(), n, MPI_DOUBLE, MPI_COMM_WORLD),
        "MPI_Allgather");
  bytes_ += 8.0 * n * (size_ - 1), messages_ += size_ - 1;
  for (int k = 0; k < n; ++k) {
    double s = 0;
    for (int r = 0; r < size_; ++r) s += all[std::size_t(r) * std::size_t(n) + std::size_t(k)];
    v[k] = s;
  }
}

/// One double reduced over the ranks by `op` (min or max: exact in any order).
static double reduce_one(double v, MPI_Op op, double& bytes, double& messages) {
  double out = v;
  check(MPI_Allreduce(&v, &out, 1, MPI_DOUBLE, op, MPI_COMM_WORLD), "MPI_Allreduce");
  bytes += 8, messages += 1;
  return out;
}

double Comm::min(double v) const {
  return size_ == 1 ? v : reduce_one(v, MPI_MIN, bytes_, messages_);
}

double Comm::max(double v) const {
  return size_ == 1 ? v : reduce_one(v, MPI_MAX, bytes_, messages_);
}

std::vector<std::string> Comm::all_gather(const std::string& mine) const {
  if (size_ == 1) return {mine};
  int n = count_of(mine.size());
  std::vector<int> counts(static_cast<std::size_t>(size_)), displs;
  check(MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD), "MPI_Allgather");
  std::string all(displacements(counts, displs), '\0');
  check(MPI_Allgatherv(mine.data(), n, MPI_BYTE, all.data(), counts.data(), displs.data(), MPI_BYTE,
                       MPI_COMM_WORLD),
        "MPI_Allgatherv");
  bytes_ += double(n) * (size_ - 1), messages_ += 2.0 * (size_ - 1);
  std::vector<std::string> out(static_cast<std::size_t>(size_));
  for (int r = 0; r < size_; ++r)
    out[std::size_t(r)] = all.substr(std::size_t(displs[r]), counts[r]);
  return out;
}

std::string Comm::gather(const std::string& mine, std::vector<std::size_t>& offsets) const {
  offsets.clear();
  if (size_ == 1) {
    offsets = {0, mine.size()};
    return mine;
  }
  int n = count_of(mine.size());
  std::vector<int> counts(static_cast<std::size_t>(size_)), displs;
  check(MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD), "MPI_Gather");
  const std::size_t total = displacements(counts, displs);  // zeros but at the root
  std::string all(total, '\0');
  check(MPI_Gatherv(mine.data(), n, MPI_BYTE, all.data(), counts.data(), displs.data(), MPI_BYTE, 0,
                    MPI_COMM_WORLD),
        "MPI_Gatherv");
  if (!root()) bytes_ += n, messages_ += 2;
  if (root()) {
    for (int r = 0; r < size_; ++r) offsets.push_back(std::size_t(displs[r]));
    offsets.push_back(total);
  }
  return all;
}

void Comm::broadcast(std::string& bytes) const {
  if (size_ == 1) return;
  unsigned long long n = bytes.size();
  check(MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD), "MPI_Bcast");
  bytes.resize(n);
  // In pieces below 2^31 bytes.
  constexpr std::size_t kPiece = std::size_t(1) << 30;
  for (std::size_t off = 0; off < n; off += kPiece)
    check(MPI_Bcast(bytes.data() + off, int(std::min<std::size_t>(kPiece, n - off)), MPI_BYTE, 0,
                    MPI_COMM_WORLD),
          "MPI_Bcast");
  if (root()) bytes_ += double(n) * (size_ - 1), messages_ += size_ - 1;
}

std::vector<std::string> Comm::all_to_all(std::vector<std::string> send) const {
  if (size_ == 1) return send;
  std::vector<int> scount(static_cast<std::size_t>(size_)), rcount(static_cast<std::size_t>(size_));
  std::vector<int> sdispl, rdispl;
  std::string out_bytes;
  for (int r = 0; r < size_; ++r) {
    scount[std::size_t(r)] = count_of(send[std::size_t(r)].size());
    out_bytes += send[std::size_t(r)];
    if (r != rank_) bytes_ += double(scount[std::size_t(r)]), messages_ += 1;
  }
  displacements(scount, sdispl);
  check(MPI_Alltoall(scount.data(), 1, MPI_INT, rcount.data(), 1, MPI_INT, MPI_COMM_WORLD),
        "MPI_Alltoall");
  std::string in_bytes(displacements(rcount, rdispl), '\0');
  check(MPI_Alltoallv(out_bytes.data(), scount.data(), sdispl.data(), MPI_BYTE, in_bytes.data(),
                      rcount.data(), rdispl.data(), MPI_BYTE, MPI_COMM_WORLD),
        "MPI_Alltoallv");
  std::vector<std::string> in(static_cast<std::size_t>(size_));
  for (int r = 0; r < size_; ++r)
    in[std::size_t(r)] = in_bytes.substr(std::size_t(rdispl[r]), rcount[r]);
  return in;
}

void Comm::exchange(const std::vector<int>& partners, const std::vector<std::vector<double>>& send,
                    std::vector<std::vector<double>>& recv) const {
  if (partners.empty()) return;
  std::vector<MPI_Request> req(2 * partners.size());
  for (std::size_t k = 0; k < partners.size(); ++k)
    check(MPI_Irecv(recv[k].data(), count_of(recv[k].size()), MPI_DOUBLE, partners[k], 7,
                    MPI_COMM_WORLD, &req[k]),
          "MPI_Irecv");
  for (std::size_t k = 0; k < partners.size(); ++k) {
    check(MPI_Isend(send[k].data(), count_of(send[k].size()), MPI_DOUBLE, partners[k], 7,
                    MPI_COMM_WORLD, &req[partners.size() + k]),
          "MPI_Isend");
    bytes_ += 8.0 * double(send[k].size()), messages_ += 1;
  }
  check(MPI_Waitall(int(req.size()), req.data(), MPI_STATUSES_IGNORE), "MPI_Waitall");
}

void Comm::abort(int status) const {
  if (mpi_) MPI_Abort(MPI_COMM_WORLD, status);
  std::exit(status);
}

#else  // one process: every collective is the identity

CommSession::CommSession(int&, char**&) {}
CommSession::~CommSession() = default;
void Comm::sum(double*, int) const {}
double Comm::min(double v) const {
  return v;
}
double Comm::max(double v) const {
  return v;
}
std::vector<std::string> Comm::all_gather(const std::string& mine) const {
  return {mine};
}
std::string Comm::gather(const std::string& mine, std::vector<std::size_t>& offsets) const {
  offsets = {0, mine.size()};
  return mine;
}
void Comm::broadcast(std::string&) const {}
std::vector<std::string> Comm::all_to_all(std::vector<std::string> send) const {
  return send;
}
void Comm::exchange(const std::vector<int>&, const std::vector<std::vector<double>>&,
                    std::vector<std::vector<double>>&) const {}
void Comm::abort(int status) const {
  std::exit(status);
}

#endif

}  // namespace mpm
