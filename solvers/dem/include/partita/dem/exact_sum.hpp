#pragma once
// The exact sum of doubles, rounded once at the end: the same bits whatever the order of the
// terms and however they are split into partial sums merged later (add(const ExactSum&)). A sum
// over the particles of a split bed (subdomain.hpp) is then the same on any split without
// gathering the terms into one order.
//
// How: every finite double is an integer times a power of two, m 2^e with |m| < 2^53 and
// e >= -1126; the accumulator holds the integer sum of all terms in units of 2^-1126 as 70 limbs
// of 32 bits (each kept in an int64, so that 2^30 additions fit before the carries are
// propagated), enough for 2^30 terms of any finite size. value() propagates the carries (a
// unique representation of the exact sum) and rounds its leading 64 bits, with a sticky bit for
// the rest, to the nearest double (ties to even; a result below the normal range may round twice).
// Non-finite terms are summed apart and returned as that sum (an infinity or NaN).
// Cost: a frexp and three integer additions a term (a few ns; not for a force pass's inner loop).

#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>

namespace partita::dem {

class ExactSum {
 public:
  void add(double x);
  void add(const ExactSum& other);
  void clear();
  /// The exact sum rounded to a double.
  double value() const;

  /// The accumulator as bytes (for a transport; both ends have the same byte order).
  static constexpr std::size_t byte_size = 70 * 8 + 8 + 8;
  void write(std::byte* out) const;
  void read(const std::byte* in);
  /// A shorter form for messages of many sums (a mesh's vertex forces over a split bed): only the
  /// limbs in use (a sum of terms of a few magnitudes uses a few of the 70), compact_size()
  /// bytes: the first limb in use and their count (u8 each), the limbs (i64), the additions
  /// since the carries were propagated (i64) and the non-finite terms' sum (f64).
  std::size_t compact_size() const;
  void write_compact(std::byte* out) const;
  /// Reads what write_compact() wrote from at most `bytes` bytes; returns the bytes it took, 0
  /// when they do not hold a compact sum (cut short, or limbs out of range).
  std::size_t read_compact(const std::byte* in, std::size_t bytes);

 private:
  static constexpr int limb_bits = 32;
  static constexpr int offset = 1126;  // bit 0 of limb 0 weighs 2^-1126
  static constexpr int limb_count = 70;
  void normalize();
  // the limbs in use: [first, first + count)
  std::pair<int, int> used() const;

  std::array<std::int64_t, limb_count> limb_{};
  std::int64_t pending_ = 0;  // additions since the last normalize()
  double special_ = 0.0;      // sum of the non-finite terms
};

}  // namespace partita::dem
