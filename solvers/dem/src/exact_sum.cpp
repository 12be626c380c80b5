// ExactSum: the integer sum of the terms in units of 2^-1126, rounded once (exact_sum.hpp).
#include "partita/dem/exact_sum.hpp"

#include <bit>
#include <cmath>
#include <cstring>

namespace partita::dem {

namespace {
__extension__ typedef unsigned __int128 uint128;  // (GCC and Clang)
constexpr std::int64_t limb_mask = 0xffffffff;
}  // namespace

void ExactSum::clear() {
  limb_.fill(0);
  pending_ = 0;
  special_ = 0.0;
}

void ExactSum::add(double x) {
  if (x == 0.0) return;
  if (!std::isfinite(x)) {
    special_ += x;
    return;
  }
  int e = 0;
  const double f = std::frexp(x, &e);                            // x = f 2^e, 1/2 <= |f| < 1
  const auto m = static_cast<std::int64_t>(std::ldexp(f, 53));  // exact: |m| < 2^53
  const int s = e - 53 + offset;                                // >= 0 (e >= -1073)
  const int k = s / limb_bits;
  const uint128 w = static_cast<uint128>(static_cast<std::uint64_t>(m < 0 ? -m : m)) << (s % limb_bits);
  const std::int64_t sign = m < 0 ? -1 : 1;
  limb_[k] += sign * static_cast<std::int64_t>(static_cast<std::uint64_t>(w) & limb_mask);
  limb_[k + 1] += sign * static_cast<std::int64_t>(static_cast<std::uint64_t>(w >> 32) & limb_mask);
  limb_[k + 2] += sign * static_cast<std::int64_t>(static_cast<std::uint64_t>(w >> 64));
  if (++pending_ >= (std::int64_t{1} << 30)) normalize();
}

// Every limb but the last into [0, 2^32), the carries upwards: the one representation of the sum.
void ExactSum::normalize() {
  for (int k = 0; k + 1 < limb_count; ++k) {
    const std::int64_t carry = limb_[k] >> limb_bits;  // (floor: arithmetic shift)
    limb_[k] -= carry * (std::int64_t{1} << limb_bits);
    limb_[k + 1] += carry;
  }
  pending_ = 0;
}

void ExactSum::add(const ExactSum& other) {
  ExactSum o = other;
  o.normalize();
  normalize();
  for (int k = 0; k < limb_count; ++k) limb_[k] += o.limb_[k];
  pending_ = 1;
  special_ += other.special_;
}

double ExactSum::value() const {
  if (special_ != 0.0 || std::isnan(special_)) return special_;
  ExactSum t = *this;
  t.normalize();
  auto& a = t.limb_;
  const bool negative = a[limb_count - 1] < 0;
  if (negative) {  // the magnitude
    for (std::int64_t& l : a) l = -l;
    t.normalize();
  }
  int h = limb_count - 1;
  while (h >= 0 && a[h] == 0) --h;
  if (h < 0) return 0.0;
  // the leading 96 bits (limbs h, h-1, h-2), shifted so that the leading one is bit 127; its top
  // 64 bits with a sticky bit for everything below, converted (rounded to nearest) and scaled
  uint128 w = 0;
  for (int k = h; k >= h - 2; --k)
    w = (w << 32) | (k >= 0 ? static_cast<uint128>(static_cast<std::uint64_t>(a[k])) : 0);
  const int shift = 32 + std::countl_zero(static_cast<std::uint32_t>(a[h]));
  w <<= shift;
  auto top = static_cast<std::uint64_t>(w >> 64);
  bool sticky = static_cast<std::uint64_t>(w) != 0;
  for (int k = h - 3; k >= 0 && !sticky; --k) sticky = a[k] != 0;
  if (sticky) top |= 1;
  const double r = std::ldexp(static_cast<double>(top), 64 - shift + limb_bits * (h - 2) - offset);
  return negative ? -r : r;
}

void ExactSum::write(std::byte* out) const {
  std::memcpy(out, limb_.data(), sizeof limb_);
  std::memcpy(out + sizeof limb_, &pending_, 8);
  std::memcpy(out + sizeof limb_ + 8, &special_, 8);
}

void ExactSum::read(const std::byte* in) {
  std::memcpy(limb_.data(), in, sizeof limb_);
  std::memcpy(&pending_, in + sizeof limb_, 8);
  std::memcpy(&special_, in + sizeof limb_ + 8, 8);
}

std::pair<int, int> ExactSum::used() const {
  int first = 0, last = limb_count;
  while (first < limb_count && limb_[first] == 0) ++first;
  if (first == limb_count) return {0, 0};
  while (limb_[last - 1] == 0) --last;
  return {first, last - first};
}

std::size_t ExactSum::compact_size() const {
  return 2 + 8 * static_cast<std::size_t>(used().second) + 16;
}

void ExactSum::write_compact(std::byte* out) const {
  const auto [first, count] = used();
  out[0] = static_cast<std::byte>(first);
  out[1] = static_cast<std::byte>(count);
  std::memcpy(out + 2, limb_.data() + first, 8 * static_cast<std::size_t>(count));
  std::memcpy(out + 2 + 8 * count, &pending_, 8);
  std::memcpy(out + 2 + 8 * count + 8, &special_, 8);
}

std::size_t ExactSum::read_compact(const std::byte* in, std::size_t bytes) {
  if (bytes < 18) return 0;
  const int first = static_cast<int>(in[0]), count = static_cast<int>(in[1]);
  const std::size_t size = 18 + 8 * static_cast<std::size_t>(count);
  if (first + count > limb_count || bytes < size) return 0;
  limb_.fill(0);
  std::memcpy(limb_.data() + first, in + 2, 8 * static_cast<std::size_t>(count));
  std::memcpy(&pending_, in + 2 + 8 * count, 8);
  std::memcpy(&special_, in + 2 + 8 * count + 8, 8);
  if (pending_ < 0 || pending_ >= (std::int64_t{1} << 30)) return 0;
  return size;
}

}  // namespace partita::dem
