#pragma once
// The dense kernels of the threaded supernodal solve (supernodal_solve.hpp), compiled twice:
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
  // y_s = L_ss^-1 y_s on the columns [j0, j1) of the block, rows below the block untouched
  void (*forward_triangle)(const SupernodeBlock& b, double* y, int j0, int j1);
  // y_s[i] -= sum_{j in [j0, j1)} L_ij y_j for the own rows i in [r0, r1), j ascending
  void (*forward_rows_below)(const SupernodeBlock& b, double* y, int j0, int j1, int r0, int r1);
  // w[i - r0] = sum_j L_ij y_j over all own columns (ascending), rows i in [r0, r1)
  void (*forward_offdiagonal)(const SupernodeBlock& b, const double* y, int r0, int r1, double* w);
  // the transposed triangle of the columns [j0, j1): y_j for j descending
  void (*backward_triangle)(const SupernodeBlock& b, double* y, int j0, int j1);
  // ys[j] -= L(r0 .. r0+m-1, j) . v for the columns j in [c0, c1)
  void (*columns_dot)(const SupernodeBlock& b, const double* v, int r0, int m, double* ys, int c0,
                      int c1);
  // a whole supernode by one thread, the same sums as the kernels above in the shared order;
  // forward: off-diagonal updates of rows below inside_end go to y, the others are added to
  // outside; w, g: work space of nrow - ncol doubles
  void (*forward_serial)(const SupernodeBlock& b, double* y, double* w, int inside_end,
                         double* outside);
  void (*backward_serial)(const SupernodeBlock& b, double* y, double* g);
};

// The best set this processor runs (AVX2 + FMA or SSE2), chosen on the first call.
const SupernodalKernels& supernodal_kernels();

}  // namespace partita::fem::detail
