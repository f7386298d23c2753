// MPI latency and bandwidth between two ranks (bench/ranks.py; the inputs of the scaling model
// in docs/performance.md): round trips of messages from 8 bytes to 16 MB between ranks 0 and 1,
// the median of 7 batches; prints one line per size, time one way and bandwidth.
//   mpirun -np 2 bench/pingpong
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>

#include <algorithm>
#include <cstdio>
#include <vector>

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (size != 2) {
    if (rank == 0) std::fprintf(stderr, "pingpong: run with mpirun -np 2\n");
    MPI_Finalize();
    return 2;
  }
  const int other = 1 - rank;
  for (std::size_t bytes = 8; bytes <= (std::size_t(16) << 20); bytes *= 8) {
    std::vector<char> buf(bytes, 1);
    const int reps = bytes <= 4096 ? 2000 : bytes <= (1 << 20) ? 100 : 10;
    std::vector<double> one_way;
    for (int batch = 0; batch < 8; ++batch) {
      MPI_Barrier(MPI_COMM_WORLD);
      const double t0 = MPI_Wtime();
      for (int r = 0; r < reps; ++r) {
        if (rank == 0) {
          MPI_Send(buf.data(), int(bytes), MPI_BYTE, other, 0, MPI_COMM_WORLD);
          MPI_Recv(buf.data(), int(bytes), MPI_BYTE, other, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        } else {
          MPI_Recv(buf.data(), int(bytes), MPI_BYTE, other, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
          MPI_Send(buf.data(), int(bytes), MPI_BYTE, other, 0, MPI_COMM_WORLD);
        }
      }
      if (batch > 0) one_way.push_back((MPI_Wtime() - t0) / (2.0 * reps));  // batch 0 warms up
    }
    std::sort(one_way.begin(), one_way.end());
    const double t = one_way[one_way.size() / 2];
    if (rank == 0)
      std::printf("%10zu bytes: %9.3f us one way, %8.1f MB/s\n", bytes, t * 1e6, bytes / t / 1e6);
  }
  MPI_Finalize();
  return 0;
}
