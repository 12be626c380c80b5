#pragma once
// The bytes of the messages between the controller and a participant in another process
// (remote_participant.cpp): a writer that appends to a buffer the caller keeps between messages
// (cleared, not freed: no allocation once it has grown to the largest message) and a reader over
// the bytes received, in place. The layout is BinaryWriter's (binary_io.hpp) without its
// sections and checksums: numbers in the machine's byte order, a text or a list as [u64 count]
// and its bytes, a matrix of doubles as [i64 rows] [i64 cols] and its values column by column
// (one memcpy). Every read is checked against the message's length: a damaged or truncated
// message is a partita::Error naming the peer, never a read past the end.

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include <Eigen/Core>

#include "partita/interface/binary_io.hpp"  // matrix_shape_problem(): the same layout
#include "partita/interface/error.hpp"

namespace partita::run {

class MessageWriter {
 public:
  /// Appends to `buffer` (the caller clears it for a new message; its capacity is kept).
  explicit MessageWriter(std::string& buffer) : buffer_(buffer) {}

  template <class T>
  requires std::is_arithmetic_v<T>
  void write(T v) { put(&v, sizeof(T)); }
  void write(std::string_view s) {
    write(static_cast<std::uint64_t>(s.size()));
    put(s.data(), s.size());
  }
  void write(const std::string& s) { write(std::string_view(s)); }
  void write(const char* s) { write(std::string_view(s)); }
  template <class T>
  requires std::is_arithmetic_v<T>
  void write(const std::vector<T>& v) {
    write(static_cast<std::uint64_t>(v.size()));
    put(v.data(), v.size() * sizeof(T));
  }
  /// A dense matrix or vector of doubles: rows, cols, the values column-major.
  template <class Derived>
  void write(const Eigen::PlainObjectBase<Derived>& m) {
    static_assert(std::is_same_v<typename Derived::Scalar, double>, "doubles only");
    write(static_cast<std::int64_t>(m.rows()));
    write(static_cast<std::int64_t>(m.cols()));
    put(m.data(), static_cast<std::size_t>(m.size()) * sizeof(double));
  }

 private:
  void put(const void* p, std::size_t n) { buffer_.append(static_cast<const char*>(p), n); }
  std::string& buffer_;
};

class MessageReader {
 public:
  /// Reads `bytes` (which must outlive the reader); `source` names the sender in messages.
  MessageReader(std::string_view bytes, const std::string& source)
      : bytes_(bytes), source_(source) {}
  MessageReader(std::string_view bytes, const std::string&& source) = delete;  // kept by reference

  template <class T>
  requires std::is_arithmetic_v<T>
  void read(T& v) { take(&v, sizeof(T), "a number"); }
  template <class T>
  requires std::is_arithmetic_v<T> T get() {
    T v{};
    read(v);
    return v;
  }
  /// Into `s`, whose storage is reused.
  void read(std::string& s) {
    const std::size_t n = count(1, "a text");
    s.assign(bytes_.data() + at_, n);
    at_ += n;
  }
  std::string get_string() {
    std::string s;
    read(s);
    return s;
  }
  /// A text as a view into the message (valid while its bytes are).
  std::string_view view_string() {
    const std::size_t n = count(1, "a text");
    const std::string_view s = bytes_.substr(at_, n);
    at_ += n;
    return s;
  }
  template <class T>
  requires std::is_arithmetic_v<T>
  void read(std::vector<T>& v) {
    const std::size_t n = count(sizeof(T), "a list");
    v.resize(n);
    take(v.data(), n * sizeof(T), "a list");
  }
  /// Into `m`, resized only where its shape differs (no allocation for a matrix of the same
  /// shape as the last one).
  template <class Derived>
  void read(Eigen::PlainObjectBase<Derived>& m) {
    const auto rows = get<std::int64_t>();
    const auto cols = get<std::int64_t>();
    if (const std::string why =
            matrix_shape_problem<Derived>(rows, cols, remaining() / sizeof(double));
        !why.empty())
      fail(why);
    if (m.rows() != rows || m.cols() != cols) m.resize(rows, cols);
    take(m.data(), static_cast<std::size_t>(rows * cols) * sizeof(double), "a matrix");
  }

  /// A [u64 count] of items of at least `item` bytes each, which must fit in what is left (a
  /// damaged count never allocates).
  std::size_t count(std::size_t item, const char* what) {
    const auto n = get<std::uint64_t>();
    if (n > remaining() / item)
      fail(std::string(what) + " of " + std::to_string(n) + " items of " + std::to_string(item) +
           " bytes or more (" + std::to_string(remaining()) + " bytes remain)");
    return static_cast<std::size_t>(n);
  }
  std::size_t remaining() const { return bytes_.size() - at_; }
  /// Throw "<source> sent a damaged message: expected <what> at byte <n> of <size>".
  [[noreturn]] void fail(const std::string& what) const {
    throw Error(source_ + " sent a damaged message: expected " + what + " at byte " +
                std::to_string(at_) + " of " + std::to_string(bytes_.size()));
  }

 private:
  void take(void* p, std::size_t n, const char* what) {
    if (n > remaining()) fail(std::string(what) + " of " + std::to_string(n) + " bytes");
    if (n > 0) std::memcpy(p, bytes_.data() + at_, n);
    at_ += n;
  }
  std::string_view bytes_;
  const std::string& source_;
  std::size_t at_ = 0;
};

}  // namespace partita::run
