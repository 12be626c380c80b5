#pragma once
// Binary state streams for restart files. Values are written in the machine's own byte order
// (restart files are for continuing a run on the same kind of machine, as LAMMPS's binary
// restart files are); the file's header records the order and a reader refuses another one.
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

class BinaryWriter {
 public:
  explicit BinaryWriter(std::ostream& out) : out_(out) {}

  template <class T>
  requires std::is_arithmetic_v<T>
  void write(T v) { put(&v, sizeof(T)); }
  void write(const std::string& s) {
    write(static_cast<std::uint64_t>(s.size()));
    put(s.data(), s.size());
  }
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

class BinaryReader {
 public:
  /// `source` names the stream in messages (a file name).
  BinaryReader(std::istream& in, std::string source) : in_(in), source_(std::move(source)) {}

  template <class T>
  requires std::is_arithmetic_v<T>
  void read(T& v) { raw(&v, sizeof(T), "a number"); }
  template <class T>
  requires std::is_arithmetic_v<T> T get() {
    T v{};
    read(v);
    return v;
  }
  void read(std::string& s) {
    const std::uint64_t n = count(1, "a text");
    s.resize(n);
    raw(s.data(), n, "a text");
  }
  std::string get_string() {
    std::string s;
    read(s);
    return s;
  }
  template <class T>
  requires std::is_arithmetic_v<T>
  void read(std::vector<T>& v) {
    const std::uint64_t n = count(sizeof(T), "a list");
    v.resize(n);
    raw(v.data(), n * sizeof(T), "a list");
  }
  template <class Derived>
  void read(Eigen::PlainObjectBase<Derived>& m) {
    const auto rows = get<std::int64_t>();
    const auto cols = get<std::int64_t>();
    if (const std::string why = matrix_shape_problem<Derived>(rows, cols, INT64_MAX / 8);
        !why.empty())
      fail(why);
    check_remaining(static_cast<std::uint64_t>(rows * cols) * sizeof(double), "a matrix");
    m.resize(rows, cols);
    raw(m.data(), static_cast<std::size_t>(rows * cols) * sizeof(double), "a matrix");
  }
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
  long long position() const { return static_cast<long long>(in_.tellg()); }
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

}  // namespace partita
