#pragma once
// One serialise function per state, for writing and reading restart data alike:
//
//   void Thing::serialize(StateArchive& ar) {
//     ar.section("thing");
//     ar.io(count_);   // written, or read back into the same member
//     ar.io(values_);
//     if (ar.reading() && values_.size() != count_) ar.fail("as many values as the count");
//   }
//
// The archive knows its direction (a BinaryWriter or a BinaryReader behind it, binary_io.hpp),
// so each field is named once and cannot be written and forgotten on reading, or read out of
// order. The bytes are exactly those of the BinaryWriter calls it stands for; a bool is one byte
// (0 or 1). A virtual serialize(StateArchive&) serves a class hierarchy (the schemes, the
// accelerations), which a template over the archive type could not.

#include <cstdint>
#include <string>
#include <type_traits>
#include <utility>

#include "partita/interface/binary_io.hpp"
#include "partita/interface/error.hpp"

namespace partita {

class StateArchive {
 public:
  explicit StateArchive(BinaryWriter& out) : out_(&out) {}
  explicit StateArchive(BinaryReader& in) : in_(&in) {}

  bool reading() const { return in_ != nullptr; }

  /// Write v, or read into it (numbers, texts, lists of numbers, Eigen matrices of doubles). A
  /// const value (computed for the file) can only be written.
  template <class T>
  void io(T& v) {
    if constexpr (std::is_const_v<T>) {
      if (in_) fail("(internal) a writable value to read into");
      out_->write(v);
    } else if (in_) {
      in_->read(v);
    } else {
      out_->write(std::as_const(v));
    }
  }
  void io(bool& b) {
    auto byte = static_cast<std::uint8_t>(b);
    io(byte);
    b = byte != 0;
  }
  /// A section marker: written, or checked on reading.
  void section(const std::string& name) {
    if (in_)
      in_->expect_section(name);
    else
      out_->section(name);
  }
  /// Reading: the reader's "damaged or from another case: expected <what> at byte N" error.
  [[noreturn]] void fail(const std::string& what) const {
    if (in_) in_->fail(what);
    throw Error("restart data: cannot write " + what);
  }

 private:
  BinaryWriter* out_ = nullptr;
  BinaryReader* in_ = nullptr;
};

}  // namespace partita
