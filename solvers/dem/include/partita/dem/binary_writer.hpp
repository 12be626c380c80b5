#pragma once
// Little helper for the DEM's binary state format: plain values and contiguous arrays written
// as raw bytes (the format records the byte order; see SystemState). Arrays are written as a
// 64-bit count followed by their elements.

#include <cstdint>
#include <ostream>
#include <string>
#include <type_traits>
#include <vector>

namespace partita::dem {

class BinaryWriter {
 public:
  explicit BinaryWriter(std::ostream& out) : out_(out) {}

  template <class T>
  void value(const T& v) {
    static_assert(std::is_standard_layout_v<T>, "raw bytes need a standard-layout type");
    out_.write(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  template <class T>
  void array(const std::vector<T>& v) {
    static_assert(std::is_standard_layout_v<T>, "raw bytes need a standard-layout type");
    value(static_cast<std::uint64_t>(v.size()));
    if (!v.empty())
      out_.write(reinterpret_cast<const char*>(v.data()),
                 static_cast<std::streamsize>(v.size() * sizeof(T)));
  }
  void array(const std::vector<bool>& v) {
    std::vector<char> c(v.begin(), v.end());
    array(c);
  }
  void string(const std::string& s) {
    value(static_cast<std::uint64_t>(s.size()));
    out_.write(s.data(), static_cast<std::streamsize>(s.size()));
  }
  std::ostream& stream() { return out_; }

 private:
  std::ostream& out_;
};

}  // namespace partita::dem
