// bench_blas_threads: may the system BLAS be called from several threads at once? The reason
// partita's threaded factorisation (solvers/fem/src/supernodal_factorize.*) has dense kernels of
// its own. For dgemm (C = A B^T), dsyrk (C = A A^T, lower) and dtrsm (X L^T = B): 400 calls of
// random sizes up to 300, each computed once alone as the reference, then all of them again on
// the OpenMP threads, 50 times over; prints how many of the threaded calls gave other bits than
// their reference (a BLAS that is safe to call from threads prints 0 for each: the same call
// on the same data is deterministic), and the per-call time alone and threaded as a ratio.
//
// usage: bench_blas_threads [--calls N] [--repeats R] [--max-size S]   (OMP_NUM_THREADS threads)
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

extern "C" {
void dgemm_(const char*, const char*, const int*, const int*, const int*, const double*,
            const double*, const int*, const double*, const int*, const double*, double*,
            const int*, std::size_t, std::size_t);
void dsyrk_(const char*, const char*, const int*, const int*, const double*, const double*,
            const int*, const double*, double*, const int*, std::size_t, std::size_t);
void dtrsm_(const char*, const char*, const char*, const char*, const int*, const int*,
            const double*, const double*, const int*, double*, const int*, std::size_t,
            std::size_t, std::size_t, std::size_t);
}

namespace {

struct Call {
  int m = 0, n = 0, k = 0;
  std::vector<double> a, b, c, reference;
};

enum class Routine { Gemm, Syrk, Trsm };

void run(Routine r, Call& x) {
  const double one = 1.0, zero = 0.0;
  switch (r) {
    case Routine::Gemm:
      dgemm_("N", "T", &x.m, &x.n, &x.k, &one, x.a.data(), &x.m, x.b.data(), &x.n, &zero,
             x.c.data(), &x.m, 1, 1);
      break;
    case Routine::Syrk:
      std::fill(x.c.begin(), x.c.end(), 0.0);
      dsyrk_("L", "N", &x.m, &x.k, &one, x.a.data(), &x.m, &zero, x.c.data(), &x.m, 1, 1);
      break;
    case Routine::Trsm:
      x.c = x.a;  // B (m x n), solved in place against the n x n lower triangle in b
      dtrsm_("R", "L", "T", "N", &x.m, &x.n, &one, x.b.data(), &x.n, x.c.data(), &x.m, 1, 1, 1, 1);
      break;
  }
}

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

int main(int argc, char** argv) {
  int calls = 400, repeats = 50, max_size = 300;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--calls" && i + 1 < argc)
      calls = std::atoi(argv[++i]);
    else if (a == "--repeats" && i + 1 < argc)
      repeats = std::atoi(argv[++i]);
    else if (a == "--max-size" && i + 1 < argc)
      max_size = std::atoi(argv[++i]);
    else {
      std::fprintf(stderr, "usage: bench_blas_threads [--calls N] [--repeats R] [--max-size S]\n");
      return 2;
    }
  }
  if (calls < 1 || repeats < 1 || max_size < 1) {
    std::fprintf(stderr, "bench_blas_threads: --calls, --repeats and --max-size must be >= 1\n");
    return 2;
  }
#ifdef _OPENMP
  const int threads = omp_get_max_threads();
#else
  const int threads = 1;
#endif
  std::printf("bench_blas_threads: %d calls of sizes 1..%d, %d repeats on %d threads\n", calls,
              max_size, repeats, threads);
  std::printf("  %-6s %12s %12s %16s\n", "call", "differing", "of", "threaded/alone");
  for (const Routine r : {Routine::Gemm, Routine::Syrk, Routine::Trsm}) {
    std::mt19937 rng(1);
    std::uniform_int_distribution<int> size(1, max_size);
    std::normal_distribution<double> value;
    std::vector<Call> xs(static_cast<std::size_t>(calls));
    for (auto& x : xs) {
      x.m = size(rng);
      x.n = size(rng);
      x.k = r == Routine::Trsm ? x.n : size(rng);
      x.a.resize(static_cast<std::size_t>(x.m) * (r == Routine::Trsm ? x.n : x.k));
      x.b.resize(static_cast<std::size_t>(x.n) * x.k);
      for (auto& v : x.a) v = value(rng);
      for (auto& v : x.b) v = value(rng);
      if (r == Routine::Trsm)  // a well-conditioned lower triangle
        for (int i = 0; i < x.n; ++i) x.b[static_cast<std::size_t>(i) * (x.n + 1)] = 10.0 + x.n;
      x.c.assign(static_cast<std::size_t>(x.m) * (r == Routine::Gemm ? x.n : r == Routine::Syrk
                                                                              ? x.m
                                                                              : x.n),
                 0.0);
    }
    const auto t0 = std::chrono::steady_clock::now();
    for (auto& x : xs) {
      run(r, x);
      x.reference = x.c;
    }
    const double alone = seconds_since(t0) / calls;
    long differing = 0;
    const auto t1 = std::chrono::steady_clock::now();
    for (int rep = 0; rep < repeats; ++rep) {
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : differing)
      for (int i = 0; i < calls; ++i) {
        Call& x = xs[static_cast<std::size_t>(i)];
        run(r, x);
        if (std::memcmp(x.c.data(), x.reference.data(), sizeof(double) * x.c.size()) != 0)
          ++differing;
      }
    }
    const double threaded = seconds_since(t1) * threads / (static_cast<double>(calls) * repeats);
    const char* name = r == Routine::Gemm ? "dgemm" : r == Routine::Syrk ? "dsyrk" : "dtrsm";
    std::printf("  %-6s %12ld %12ld %16.2f\n", name, differing,
                static_cast<long>(calls) * repeats, threaded / alone);
  }
  std::printf("  (differing > 0: the BLAS must not be called from two threads at once)\n");
  return 0;
}
