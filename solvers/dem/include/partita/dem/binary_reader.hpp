#pragma once
// Reads what BinaryWriter wrote. Every read checks the stream: a short read throws Error naming
// what was being read ("truncated state: ..."), and an array longer than `max_count` (a corrupt
// count) throws instead of allocating.

#include "partita/dem/error.hpp"

#include <cstdint>
#include <istream>
#include <string>
#include <type_traits>
#include <vector>

namespace partita::dem {

class BinaryReader {
 public:
  explicit BinaryReader(std::istream& in) : in_(in) {}

  template <class T>
  void value(T& v, const char* what) {
    static_assert(std::is_standard_layout_v<T>, "raw bytes need a standard-layout type");
    in_.read(reinterpret_cast<char*>(&v), sizeof(T));
    check(what);
  }
  template <class T>
  T value(const char* what) {
    T v{};
    value(v, what);
    return v;
  }
  template <class T>
  void array(std::vector<T>& v, const char* what) {
    static_assert(std::is_standard_layout_v<T>, "raw bytes need a standard-layout type");
    const auto n = value<std::uint64_t>(what);
    if (n > max_count / sizeof(T) + 1)
      throw Error(std::string("corrupt state: ") + what + " claims " + std::to_string(n) +
                  " entries");
    v.resize(n);
    if (n > 0)
      in_.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(n * sizeof(T)));
    check(what);
  }
  void array(std::vector<bool>& v, const char* what) {
    std::vector<char> c;
    array(c, what);
    v.assign(c.begin(), c.end());
  }
  std::string string(const char* what) {
    const auto n = value<std::uint64_t>(what);
    if (n > max_count)
      throw Error(std::string("corrupt state: ") + what + " claims " + std::to_string(n) +
                  " bytes");
    std::string s(n, '\0');
    if (n > 0) in_.read(s.data(), static_cast<std::streamsize>(n));
    check(what);
    return s;
  }
  /// Throws Error unless the next value is `expected` (a section tag or a count that must match).
  template <class T>
  void expect(const T& expected, const char* what) {
    const T found = value<T>(what);
    if (!(found == expected))
      throw Error(std::string("state does not fit this system: ") + what + " is " +
                  std::to_string(found) + " in the state, " + std::to_string(expected) + " here");
  }

  static constexpr std::uint64_t max_count = std::uint64_t{1} << 40;

 private:
  void check(const char* what) {
    if (!in_) throw Error(std::string("truncated state: the stream ended while reading ") + what);
  }
  std::istream& in_;
};

}  // namespace partita::dem
