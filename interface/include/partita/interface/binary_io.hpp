#pragma once
// The one byte layout of partita's binary data, restart files and the messages between processes
// alike (LayoutWriter, LayoutReader): numbers in the machine's own byte order, a text or a list
// of numbers as [u64 count] and its bytes, a dense matrix of doubles as [i64 rows] [i64 cols] and
// its values column by column. Two kinds of stream share it:
// - restart files (BinaryWriter, BinaryReader) over std::ostream / std::istream, with named
//   sections and their checksums (below). Restart files are for continuing a run on the same
//   kind of machine, as LAMMPS's binary restart files are; the file's header records the byte
//   order and a reader refuses another one.
// - messages between processes (MessageWriter, MessageReader) over a buffer kept for the run,
//   without sections or checksums: a writer appends to the caller's buffer (cleared, not freed:
//   no allocation once it has grown to the largest message), a reader reads the bytes received
//   in place.
//
//   BinaryWriter w(stream);                BinaryReader r(stream, "out/run/restart/w000100.bin");
//   w.section("exchange");                 r.expect_section("exchange");
//   w.write(matrix);                       r.read(matrix);
//
// Every read is checked: a truncated stream, a section name that differs from the one expected
// or a size that cannot fit what remains gives partita::Error naming the source and what was
// expected, never a crash or a silently wrong state.
//
// Integrity: the writer keeps a CRC-32 (zlib's, the polynomial of gzip and PNG) of each section,
// the bytes from one marker to the next (the bytes before the first marker form the section
// "header"), and finish() appends a table of them:
//   [u64 count] count x ([string name][u64 offset][u64 length][u32 crc])    the table
//   [u64 table offset][u32 CRC-32 of the table][8 bytes "PRTCRC01"]         the footer (20 bytes)
// A reader calls verify_checksums() before it uses anything: every section's bytes are checked
// against the table (one pass over the file), so a flipped bit anywhere is an error naming the
// section, never a resumed run with a moved particle. Reads then stop at the table.
//
// A state that is written and read back (a part of a restart file) does both through one
// function over a StateArchive (state_archive.hpp), which writes or reads each field as named.

#include <cstdint>
#include <cstring>
#include <istream>
#include <ostream>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "partita/interface/error.hpp"

namespace partita {

/// Why a matrix announced as `rows` x `cols` doubles cannot be read into a `Derived` when at
/// most `max_values` values can follow (a negative or too large size, another shape than a
/// fixed one); empty when it can. For the readers of this layout (BinaryReader, the messages
/// between processes).
template <class Derived>
std::string matrix_shape_problem(std::int64_t rows, std::int64_t cols, std::uint64_t max_values) {
  static_assert(std::is_same_v<typename Derived::Scalar, double>, "doubles only");
  if (rows < 0 || cols < 0 ||
      (rows > 0 && static_cast<std::uint64_t>(cols) > max_values / static_cast<std::uint64_t>(rows)))
    return "a matrix of " + std::to_string(rows) + " x " + std::to_string(cols) + " values";
  if ((Derived::RowsAtCompileTime != Eigen::Dynamic && rows != Derived::RowsAtCompileTime) ||
      (Derived::ColsAtCompileTime != Eigen::Dynamic && cols != Derived::ColsAtCompileTime))
    return "a matrix of another shape than " + std::to_string(rows) + " x " + std::to_string(cols);
  return {};
}

/// The layout's writer: each value's bytes go to the stream type `Sink` (which defines
/// put(const void*, std::size_t); CRTP, so a value costs one inlined copy).
template <class Sink>
class LayoutWriter {
 public:
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
  /// Any dense Eigen matrix or vector of doubles (rows, cols, column-major values).
  template <class Derived>
  void write(const Eigen::PlainObjectBase<Derived>& m) {
    static_assert(std::is_same_v<typename Derived::Scalar, double>, "doubles only");
    write(static_cast<std::int64_t>(m.rows()));
    write(static_cast<std::int64_t>(m.cols()));
    put(m.data(), static_cast<std::size_t>(m.size()) * sizeof(double));
  }

 protected:
  LayoutWriter() = default;
  ~LayoutWriter() = default;

 private:
  void put(const void* p, std::size_t n) { static_cast<Sink&>(*this).put(p, n); }
};

/// The layout's reader over the stream type `Source`, which defines
///   take(void* p, std::size_t n, const char* what)   n bytes into p, or fail
///   count(std::size_t item, const char* what)        a [u64 count] of items of at least
///                                                    `item` bytes that fit in what remains
///   max_doubles()                                    the most doubles a matrix may announce
///   fits(std::uint64_t bytes, const char* what)      fail unless that many bytes remain
///   fail(const std::string& what)                    throw partita::Error naming the source
/// Every read is checked: a damaged size never allocates, a short stream is an error.
template <class Source>
class LayoutReader {
 public:
  template <class T>
  requires std::is_arithmetic_v<T>
  void read(T& v) { source().take(&v, sizeof(T), "a number"); }
  template <class T>
  requires std::is_arithmetic_v<T> T get() {
    T v{};
    read(v);
    return v;
  }
  /// Into `s`, whose storage is reused.
  void read(std::string& s) {
    const auto n = static_cast<std::size_t>(source().count(1, "a text"));
    s.resize(n);
    source().take(s.data(), n, "a text");
  }
  std::string get_string() {
    std::string s;
    read(s);
    return s;
  }
  template <class T>
  requires std::is_arithmetic_v<T>
  void read(std::vector<T>& v) {
    const auto n = static_cast<std::size_t>(source().count(sizeof(T), "a list"));
    v.resize(n);
    source().take(v.data(), n * sizeof(T), "a list");
  }
  /// Into `m`, resized only where its shape differs (no allocation for a matrix of the same
  /// shape as the last one).
  template <class Derived>
  void read(Eigen::PlainObjectBase<Derived>& m) {
    const auto rows = get<std::int64_t>();
    const auto cols = get<std::int64_t>();
    if (const std::string why = matrix_shape_problem<Derived>(rows, cols, source().max_doubles());
        !why.empty())
      source().fail(why);
    const auto bytes = static_cast<std::size_t>(rows * cols) * sizeof(double);
    source().fits(bytes, "a matrix");
    if (m.rows() != rows || m.cols() != cols) m.resize(rows, cols);
    source().take(m.data(), bytes, "a matrix");
  }

 protected:
  LayoutReader() = default;
  ~LayoutReader() = default;

 private:
  Source& source() { return static_cast<Source&>(*this); }
};

/// A restart stream: the layout, with named sections and their checksums (see above).
class BinaryWriter : public LayoutWriter<BinaryWriter> {
 public:
  explicit BinaryWriter(std::ostream& out) : out_(out) {}

  /// A named marker; the reader checks it (catches a reader and writer out of step). It also
  /// starts a new checksummed section.
  void section(const std::string& name);
  /// Raw bytes of a nested stream (a solver's own format), length first.
  void bytes(const std::string& b) { write(b); }
  /// Append the checksum table and footer (see above); nothing may be written after it.
  void finish();

  /// What a writer wrote, split at its sections: the bytes before the first marker, then each
  /// section's name and the bytes after its marker. A participant in another process writes its
  /// restart data into memory and sends the recording; replay() writes it into the run's file
  /// with the same bytes and checksum table as if written there.
  struct Recording {
    std::string header;
    std::vector<std::pair<std::string, std::string>> sections;
  };
  /// Split `bytes`, everything this writer wrote to its stream (an std::ostringstream's str()),
  /// at the sections it made; nothing may be written after it.
  Recording recording(const std::string& bytes);
  /// Write a recording as its writer wrote it: the header's bytes, then per section
  /// section(name) and its bytes.
  void replay(const Recording& r);

  bool good() const { return static_cast<bool>(out_); }

 private:
  friend class LayoutWriter<BinaryWriter>;
  struct Section {
    std::string name;
    std::uint64_t offset = 0;
    std::uint64_t length = 0;
    std::uint32_t crc = 0;
  };
  void put(const void* p, std::size_t n);
  void close_section();
  std::ostream& out_;
  std::uint64_t size_ = 0;  // bytes written so far
  Section current_{"header", 0, 0, 0};
  std::vector<Section> sections_;
  bool finished_ = false;
};

/// A restart stream read back: the layout, its sections checked by name and checksum.
class BinaryReader : public LayoutReader<BinaryReader> {
 public:
  /// `source` names the stream in messages (a file name).
  BinaryReader(std::istream& in, std::string source) : in_(in), source_(std::move(source)) {}

  /// Check the next marker is `name` (written by BinaryWriter::section).
  void expect_section(const std::string& name) {
    std::string s;
    read(s);
    // (built with +=: GCC 12 warns falsely on "literal" + std::string, bug 105651)
    const std::string_view mark = "§";
    const bool marked = s.rfind(mark, 0) == 0;
    if (marked && std::string_view(s).substr(mark.size()) == name) return;
    std::string what = "the section '";
    what += name;
    what += "', found ";
    if (marked) {
      what += '\'';
      what.append(s, mark.size());
      what += '\'';
    } else {
      what += "other data";
    }
    fail(what);
  }
  std::string bytes() { return get_string(); }

  /// The bytes from here up to the next section (in the verified checksum table) whose name
  /// `stop` accepts, or up to the table; the position moves past them. Only after
  /// verify_checksums() (the table says where sections start).
  template <class Stop>
  std::string raw_until(Stop stop) {
    if (limit_ < 0) fail("a verified stream (internal: raw_until before verify_checksums)");
    const std::streamoff here = in_.tellg();
    std::streamoff to = limit_;
    for (const auto& [name, offset] : table_)
      if (offset > here && stop(name)) {
        to = offset;
        break;
      }
    std::string b(static_cast<std::size_t>(to - here), '\0');
    raw(b.data(), b.size(), "a participant's data");
    return b;
  }

  /// Check every section against the checksum table that BinaryWriter::finish() wrote, before
  /// anything is read: an Error naming the damaged section (or the missing table). Reads after
  /// it end at the table. The stream position is kept.
  void verify_checksums();

  const std::string& source() const { return source_; }
  /// Throw "<source>: restart data ends or differs where <what> was expected".
  [[noreturn]] void fail(const std::string& what) const {
    throw Error(source_ + ": restart data is damaged or from another case: expected " + what +
                " at byte " + std::to_string(position()));
  }

 private:
  friend class LayoutReader<BinaryReader>;
  long long position() const { return static_cast<long long>(in_.tellg()); }
  // LayoutReader's hooks
  void take(void* p, std::size_t n, const char* what) { raw(p, n, what); }
  static std::uint64_t max_doubles() { return INT64_MAX / 8; }
  void fits(std::uint64_t n, const char* what) { check_remaining(n, what); }
  void raw(void* p, std::size_t n, const char* what) {
    if (n == 0) return;
    if (limit_ >= 0) {  // verified: the data ends at the checksum table
      const auto here = in_.tellg();
      if (here >= 0 && (here > limit_ || n > static_cast<std::uint64_t>(limit_ - here)))
        throw Error(source_ + ": restart data is truncated: " + what + " of " +
                    std::to_string(n) + " bytes runs into the checksum table");
    }
    in_.read(static_cast<char*>(p), static_cast<std::streamsize>(n));
    if (static_cast<std::size_t>(in_.gcount()) != n) {
      in_.clear();
      throw Error(source_ + ": restart data is truncated: " + what + " of " + std::to_string(n) +
                  " bytes is cut off");
    }
  }
  std::uint64_t count(std::size_t item, const char* what) {
    const auto n = get<std::uint64_t>();
    if (item > 0 && n > UINT64_MAX / item) fail(std::string(what) + " of sensible length");
    check_remaining(n * item, what);
    return n;
  }
  // A length must fit in what is left of the stream (a damaged length never allocates).
  void check_remaining(std::uint64_t n, const char* what) {
    const auto here = in_.tellg();
    if (here < 0) return;  // not seekable: the read itself checks
    std::streamoff end = limit_;
    if (end < 0) {
      in_.seekg(0, std::ios::end);
      end = in_.tellg();
      in_.seekg(here);
    }
    if (end >= here && n > static_cast<std::uint64_t>(end - here))
      throw Error(source_ + ": restart data is truncated or damaged: " + what + " of " +
                  std::to_string(n) + " bytes is announced, " +
                  std::to_string(static_cast<long long>(end - here)) + " remain");
  }

  std::istream& in_;
  std::string source_;
  std::streamoff limit_ = -1;  // where the data ends (the checksum table), once verified
  std::vector<std::pair<std::string, std::streamoff>> table_;  // sections' names and offsets
};

/// A message between processes: the layout appended to a buffer the caller keeps between
/// messages (the caller clears it for a new message; its capacity is kept).
class MessageWriter : public LayoutWriter<MessageWriter> {
 public:
  explicit MessageWriter(std::string& buffer) : buffer_(buffer) {}

 private:
  friend class LayoutWriter<MessageWriter>;
  void put(const void* p, std::size_t n) { buffer_.append(static_cast<const char*>(p), n); }
  std::string& buffer_;
};

/// A message received, read in place. Every read is checked against the message's length: a
/// damaged or truncated message is a partita::Error naming the peer, never a read past the end.
class MessageReader : public LayoutReader<MessageReader> {
 public:
  /// Reads `bytes` (which must outlive the reader); `source` names the sender in messages.
  MessageReader(std::string_view bytes, const std::string& source)
      : bytes_(bytes), source_(source) {}
  MessageReader(std::string_view bytes, const std::string&& source) = delete;  // kept by reference

  /// A text as a view into the message (valid while its bytes are).
  std::string_view view_string() {
    const std::size_t n = count(1, "a text");
    const std::string_view s = bytes_.substr(at_, n);
    at_ += n;
    return s;
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
  friend class LayoutReader<MessageReader>;
  // LayoutReader's hooks (count and fail above)
  void take(void* p, std::size_t n, const char* what) {
    if (n > remaining()) fail(std::string(what) + " of " + std::to_string(n) + " bytes");
    if (n > 0) std::memcpy(p, bytes_.data() + at_, n);
    at_ += n;
  }
  std::uint64_t max_doubles() const { return remaining() / sizeof(double); }
  void fits(std::uint64_t, const char*) const {}  // max_doubles() held the matrix to what remains
  std::string_view bytes_;
  const std::string& source_;
  std::size_t at_ = 0;
};

}  // namespace partita
