// The dense kernels of the threaded factorisation (solvers/fem/src/supernodal_kernels.hpp, an
// internal header). What must hold: C -= A B^T is the product to round-off (against long-double
// sums); each entry is one chain over k, so the packed path (large products, blocks of k and
// columns) and the in-place path give the same bits; the panel Cholesky reproduces A = L L^T and
// solving rows in separate blocks gives the bits of factorising them with the panel; a pivot
// that is not positive is reported at its column.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "../../../solvers/fem/src/supernodal_kernels.hpp"

using partita::fem::detail::factor_kernels;
using partita::fem::detail::FactorKernels;
using partita::fem::detail::kFactorPackSize;

namespace {

std::vector<double> random_matrix(int rows, int cols, int ld, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> m(static_cast<std::size_t>(ld) * cols);
  for (auto& v : m) v = u(rng);
  (void)rows;
  return m;
}

}  // namespace

TEST_CASE("factor kernels: C -= A B^T to round-off, packed and in place the same bits",
          "[fem][linear-solver][threaded-factorisation]") {
  const FactorKernels& k = factor_kernels();
  INFO("kernels " << k.name);
  std::vector<double> pack(static_cast<std::size_t>(kFactorPackSize));
  // sizes around the blocks (12 rows, 4 columns, 256 k, 128 columns) and the packing threshold
  for (const auto& size : {std::vector<int>{5, 3, 7}, std::vector<int>{37, 11, 40},
                           std::vector<int>{100, 130, 300}, std::vector<int>{300, 257, 520}}) {
    const int m = size[0], n = size[1], kk = size[2];
    const int lda = m + 3, ldb = n + 5, ldc = m + 1;
    INFO("m " << m << " n " << n << " k " << kk);
    const auto a = random_matrix(m, kk, lda, 1), b = random_matrix(n, kk, ldb, 2);
    const auto c0 = random_matrix(m, n, ldc, 3);
    std::vector<double> packed = c0, direct = c0;
    k.gemm_nt_minus(m, n, kk, a.data(), lda, b.data(), ldb, packed.data(), ldc, pack.data());
    k.gemm_nt_minus(m, n, kk, a.data(), lda, b.data(), ldb, direct.data(), ldc, nullptr);
    double worst = 0.0;
    bool same = true;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < m; ++i) {
        long double s = c0[i + static_cast<std::size_t>(j) * ldc];
        for (int q = 0; q < kk; ++q)
          s -= static_cast<long double>(a[i + static_cast<std::size_t>(q) * lda]) *
               b[j + static_cast<std::size_t>(q) * ldb];
        const std::size_t at = i + static_cast<std::size_t>(j) * ldc;
        worst = std::max(worst, std::abs(static_cast<double>(s) - packed[at]));
        same = same && packed[at] == direct[at];
      }
    // |a b| <= 1: each of the k terms rounds by at most eps times the running sum's size
    CHECK(worst <= 4.0 * kk * 2.3e-16 * std::sqrt(static_cast<double>(kk)));
    CHECK(same);
  }
}

TEST_CASE("factor kernels: the panel Cholesky gives L L^T = A, and rows solved apart give the same bits",
          "[fem][linear-solver][threaded-factorisation]") {
  const FactorKernels& k = factor_kernels();
  std::vector<double> pack(static_cast<std::size_t>(kFactorPackSize));
  // a panel of 150 rows and 70 columns: its 70 x 70 triangle and 80 rows below, from a random
  // m x 70 matrix G: A = G G^T + 70 I on the triangle's rows (SPD), the rows below G's rows
  // times the triangle's columns
  const int n = 70, m = 150, ld = m;
  const auto g = random_matrix(m, n, m, 7);
  std::vector<double> p(static_cast<std::size_t>(ld) * n, 0.0);
  for (int j = 0; j < n; ++j)
    for (int i = j; i < m; ++i) {
      double s = i == j ? n : 0.0;
      for (int q = 0; q < n; ++q) s += g[i + q * m] * g[j + q * m];
      p[i + static_cast<std::size_t>(j) * ld] = s;
    }
  const std::vector<double> a = p;
  std::vector<double> whole = p, apart = p;
  REQUIRE(k.panel_factor(n, whole.data(), ld, m, pack.data()) == -1);
  // the triangle alone, then the rows below in blocks of 33 (one of them in place: no pack)
  REQUIRE(k.panel_factor(n, apart.data(), ld, n, pack.data()) == -1);
  for (int r0 = n; r0 < m; r0 += 33)
    k.panel_solve_rows(n, apart.data(), ld, r0, std::min(m, r0 + 33),
                       r0 == n ? nullptr : pack.data());
  bool same = true;
  double worst = 0.0;
  for (int j = 0; j < n; ++j)
    for (int i = j; i < m; ++i) {
      const std::size_t at = i + static_cast<std::size_t>(j) * ld;
      same = same && whole[at] == apart[at];
      long double s = 0.0L;  // (L L^T)(i, j)
      for (int q = 0; q <= j; ++q)
        s += static_cast<long double>(whole[i + static_cast<std::size_t>(q) * ld]) *
             whole[j + static_cast<std::size_t>(q) * ld];
      worst = std::max(worst, std::abs(static_cast<double>(s) - a[at]) / n);
    }
  CHECK(same);
  CHECK(worst <= 1e-13);

  // a pivot that is not positive: column 40's diagonal entry made negative
  std::vector<double> bad = a;
  bad[40 + static_cast<std::size_t>(40) * ld] = -1.0;
  CHECK(k.panel_factor(n, bad.data(), ld, m, pack.data()) == 40);
}
