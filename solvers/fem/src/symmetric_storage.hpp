#pragma once
#include <span>

#include "partita/fem/types.hpp"

namespace partita::fem {

// A symmetric 3x3 tensor stored as 6 history values xx yy zz xy yz zx (tensor components).
inline Mat3 unpack_symmetric(std::span<const double> v) {
  Mat3 m;
  m << v[0], v[3], v[5], v[3], v[1], v[4], v[5], v[4], v[2];
  return m;
}

// Stores sym(m): the off-diagonal pairs averaged (exact for a symmetric m).
inline void pack_symmetric(const Mat3& m, std::span<double> v) {
  v[0] = m(0, 0);
  v[1] = m(1, 1);
  v[2] = m(2, 2);
  v[3] = 0.5 * (m(0, 1) + m(1, 0));
  v[4] = 0.5 * (m(1, 2) + m(2, 1));
  v[5] = 0.5 * (m(0, 2) + m(2, 0));
}

}  // namespace partita::fem
