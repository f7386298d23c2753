// The machine's own roofline: memory bandwidth (a STREAM-like triad, a = b + s c, 24 bytes an
// element as STREAM counts them) and floating-point throughput (independent fused
// multiply-add chains, 2 flops each), at 1 and 2 threads, and the core's clock. Prints a table
// and, with --json, JSON.
#include <omp.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <vector>

namespace {

double triad_gbs(int threads, std::size_t n, int repeats) {
  std::vector<double> a(n), b(n, 1.0), c(n, 2.0);
  const double s = 3.0;
  std::vector<double> times;
  for (int r = 0; r < repeats; ++r) {
    const double t0 = omp_get_wtime();
#pragma omp parallel for schedule(static) num_threads(threads)
    for (std::size_t i = 0; i < n; ++i) a[i] = b[i] + s * c[i];
    times.push_back(omp_get_wtime() - t0);
  }
  std::sort(times.begin(), times.end());
  volatile double sink = a[n / 2];
  (void)sink;
  return 24.0 * double(n) / times[times.size() / 2] / 1e9;  // median
}

// The widest vector the build targets (AVX-512; else 32 bytes: AVX2, or SSE2 pairs without
// -march=native), and enough independent chains of it to cover the FMA latency on both units,
// all in registers. A chain array in memory (as this kernel had) measures the L1 cache's load
// and store ports instead: 4.4 times below the peak on this project's Intel host.
#if defined(__AVX512F__)
constexpr int kVectorBytes = 64, kChains = 16;  // 32 zmm registers
#else
constexpr int kVectorBytes = 32, kChains = 12;  // 16 ymm registers
#endif
typedef double Vd __attribute__((vector_size(kVectorBytes)));
constexpr int kLanes = kVectorBytes / int(sizeof(double));

double fma_gflops(int threads, long iterations, int repeats) {
  std::vector<double> times;
  double total = 0;
  for (int r = 0; r < repeats; ++r) {
    const double t0 = omp_get_wtime();
#pragma omp parallel num_threads(threads) reduction(+ : total)
    {
      Vd acc[kChains];
      for (int k = 0; k < kChains; ++k)
        for (int l = 0; l < kLanes; ++l)
          acc[k][l] = 1.0 + 1e-3 * (k * kLanes + l) + omp_get_thread_num();
      const Vd x = Vd{} + 0.999999, y = Vd{} + 1e-7;
      for (long it = 0; it < iterations; ++it) {
#pragma GCC unroll 16
        for (int k = 0; k < kChains; ++k) acc[k] = acc[k] * x + y;  // one FMA each
      }
      for (int k = 0; k < kChains; ++k)
        for (int l = 0; l < kLanes; ++l) total += acc[k][l];
    }
    times.push_back(omp_get_wtime() - t0);
  }
  std::sort(times.begin(), times.end());
  volatile double sink = total;
  (void)sink;
  return 2.0 * kChains * kLanes * double(iterations) * threads / times[times.size() / 2] / 1e9;
}

// The core's clock while it runs: a chain of dependent integer additions retires one a cycle
// (x86-64; 0 elsewhere). The time-stamp counter and /proc/cpuinfo give the nominal rate, not
// the boosted one the kernels run at.
double clock_ghz() {
#if defined(__x86_64__)
  std::vector<double> rates;
  for (int r = 0; r < 5; ++r) {
    long x = 0;
    const long n = 200000000;
    const double t0 = omp_get_wtime();
    for (long i = 0; i < n; i += 10)
      __asm__ volatile(
          "add $1,%0\n\tadd $1,%0\n\tadd $1,%0\n\tadd $1,%0\n\tadd $1,%0\n\t"
          "add $1,%0\n\tadd $1,%0\n\tadd $1,%0\n\tadd $1,%0\n\tadd $1,%0"
          : "+r"(x));
    rates.push_back(double(x) / (omp_get_wtime() - t0) / 1e9);
  }
  std::sort(rates.begin(), rates.end());
  return rates[rates.size() / 2];
#else
  return 0.0;
#endif
}

}  // namespace

int main(int argc, char** argv) {
  const bool json = argc > 1 && std::strcmp(argv[1], "--json") == 0;
  const std::size_t n = std::size_t(1) << 25;  // 3 x 256 MB, far beyond the caches
  double bw[3] = {0, 0, 0}, fl[3] = {0, 0, 0};
  for (int t = 1; t <= 2; ++t) {
    bw[t] = triad_gbs(t, n, 9);
    fl[t] = fma_gflops(t, 4000000, 5);
  }
  const double ghz = clock_ghz();
  if (json) {
    std::printf(
        "{\"triad_GBs\": {\"1\": %.2f, \"2\": %.2f}, \"fma_GFLOPs\": {\"1\": %.2f, \"2\": %.2f}, "
        "\"clock_GHz\": %.3f}\n",
        bw[1], bw[2], fl[1], fl[2], ghz);
  } else {
    std::printf("%-8s %16s %16s %12s\n", "threads", "triad GB/s", "FMA GFLOP/s", "ridge flop/B");
    for (int t = 1; t <= 2; ++t)
      std::printf("%-8d %16.2f %16.2f %12.2f\n", t, bw[t], fl[t], fl[t] / bw[t]);
    std::printf("core clock %.3f GHz (dependent additions)\n", ghz);
  }
  return 0;
}
