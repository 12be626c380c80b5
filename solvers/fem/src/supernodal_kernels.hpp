#pragma once
// The dense kernels of the threaded supernodal solve (supernodal_solve.hpp) and, below, of the
// threaded factorisation (supernodal_factorize.hpp), compiled twice:
// for any x86-64 (SSE2) and, where the compiler can, for AVX2 with FMA, chosen once at run time
// by the processor. A solve is memory-bound only once its kernels stream a double per cycle or
// more; with SSE2 alone they execute about three times CHOLMOD's (OpenBLAS's) instructions.
// Every sum is formed in a fixed order, so a kernel set gives the same bits on any thread count
// (AVX2 + FMA and SSE2 differ by round-off: the fused multiply-add rounds once).

namespace partita::fem::detail {

// Supernode s of the factor: columns k1 .. k1 + ncol - 1, rows[0 .. nrow) (its own columns
// first), values l column-major with leading dimension nrow.
struct SupernodeBlock {
  int k1, ncol, nrow;
  const int* rows;
  const double* l;
};

// Columns of a block of a supernode's triangle (fixed: it sets the order of the backward sums).
constexpr int kSupernodeBlock = 64;

struct SupernodalKernels {
  const char* name;
  // One supernode by one thread. Forward: y_s = L_ss^-1 y_s (row i's updates subtracted in
  // ascending column order, blocks of kSupernodeBlock columns), then w = L_os y_s (each row's sum
  // over the columns ascending); the off-diagonal rows below inside_end get y_r -= w, the others
  // outside[r] += w. Backward: y_s -= L_os^T g (g: y gathered at the off-diagonal rows), then
  // y_s = L_ss^-T y_s by blocks from the last. w, g: work space of nrow - ncol doubles.
  void (*forward_serial)(const SupernodeBlock& b, double* y, double* w, int inside_end,
                         double* outside);
  void (*backward_serial)(const SupernodeBlock& b, double* y, double* g);
  // The pieces, for a supernode whose rows or columns the threads share (the same sums):
  // the diagonal triangle forward (all of it: y_s = L_ss^-1 y_s);
  void (*forward_diagonal)(const SupernodeBlock& b, double* y);
  // w[i - r0] = sum_j L_ij y_j over all own columns (ascending), off-diagonal rows [r0, r1);
  void (*forward_offdiagonal)(const SupernodeBlock& b, const double* y, int r0, int r1, double* w);
  // y_j -= L(ncol .. nrow-1, j) . g for the columns j in [c0, c1) (c0 even: pairs as the serial);
  void (*backward_offdiagonal)(const SupernodeBlock& b, const double* g, double* y, int c0, int c1);
  // the diagonal triangle backward (all of it: y_s = L_ss^-T y_s)
  void (*backward_diagonal)(const SupernodeBlock& b, double* y);
};

// The best set this processor runs (AVX2 + FMA or SSE2), chosen on the first call.
const SupernodalKernels& supernodal_kernels();

// The dense kernels of the threaded factorisation (supernodal_factorize.hpp), in the same two
// sets. Column-major blocks with leading dimensions; every entry's sum is formed in one fixed
// order (from zero over k ascending, then subtracted), whichever block of the output or thread
// computes it, so a set gives the same bits on any thread count.
constexpr int kPanelBlock = 32;  // columns of a supernode factorised together
constexpr int kGemmK = 256;      // the products' packed blocks: k's
constexpr int kGemmN = 128;      // and columns
constexpr int kFactorPackSize = 12 * kGemmK + kGemmN * kGemmK;  // doubles of a pack buffer
struct FactorKernels {
  const char* name;
  // C -= A B^T: C m x n, A m x k, B n x k; each entry c := c - a_0 b_0 - a_1 b_1 - ... in turn.
  // pack: kFactorPackSize doubles of the caller's (one per thread), or nullptr (in place).
  void (*gemm_nt_minus)(int m, int n, int k, const double* a, int lda, const double* b, int ldb,
                        double* c, int ldc, double* pack);
  // Cholesky of a supernode's panel P (leading dimension ld): the n x n triangle and the rows
  // [n, rows_end) below it, left-looking by blocks of kPanelBlock columns. Returns the column of
  // a pivot that is not positive (the panel is then incomplete), else -1.
  int (*panel_factor)(int n, double* p, int ld, int rows_end, double* pack);
  // Rows [r0, r1) below the factorised triangle: P_r := P_r L^-T, the same operations as
  // panel_factor does on its own rows.
  void (*panel_solve_rows)(int n, double* p, int ld, int r0, int r1, double* pack);
};
const FactorKernels& factor_kernels();

}  // namespace partita::fem::detail
