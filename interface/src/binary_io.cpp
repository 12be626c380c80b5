// BinaryWriter's section checksums and BinaryReader's check of them (binary_io.hpp).

#include "partita/interface/binary_io.hpp"

#include <algorithm>
#include <array>
#include <limits>

#include <zlib.h>

namespace partita {

namespace {

constexpr char kTrailer[8] = {'P', 'R', 'T', 'C', 'R', 'C', '0', '1'};
constexpr std::size_t kFooterSize = 8 + 4 + sizeof(kTrailer);

// zlib's crc32 takes a uInt length: feed it in pieces below 2^31 bytes.
std::uint32_t crc_update(std::uint32_t crc, const void* p, std::size_t n) {
  const auto* b = static_cast<const Bytef*>(p);
  while (n > 0) {
    const std::size_t piece = std::min<std::size_t>(n, std::size_t{1} << 30);
    crc = static_cast<std::uint32_t>(::crc32(crc, b, static_cast<uInt>(piece)));
    b += piece;
    n -= piece;
  }
  return crc;
}

template <class T>
void append(std::string& s, const T& v) {
  s.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

}  // namespace

void BinaryWriter::put(const void* p, std::size_t n) {
  if (n == 0) return;
  if (finished_) throw Error("internal: a restart stream was written after its checksum table");
  out_.write(static_cast<const char*>(p), static_cast<std::streamsize>(n));
  current_.crc = crc_update(current_.crc, p, n);
  size_ += n;
}

void BinaryWriter::close_section() {
  current_.length = size_ - current_.offset;
  if (current_.length > 0 || current_.name != "header") sections_.push_back(current_);
}

void BinaryWriter::section(const std::string& name) {
  close_section();
  current_ = Section{name, size_, 0, 0};
  write("§" + name);
}

void BinaryWriter::finish() {
  if (finished_) return;
  close_section();
  finished_ = true;
  std::string table;
  append(table, static_cast<std::uint64_t>(sections_.size()));
  for (const Section& s : sections_) {
    append(table, static_cast<std::uint64_t>(s.name.size()));
    table += s.name;
    append(table, s.offset);
    append(table, s.length);
    append(table, s.crc);
  }
  std::string footer;
  append(footer, size_);
  append(footer, crc_update(0, table.data(), table.size()));
  footer.append(kTrailer, sizeof(kTrailer));
  out_.write(table.data(), static_cast<std::streamsize>(table.size()));
  out_.write(footer.data(), static_cast<std::streamsize>(footer.size()));
}

BinaryWriter::Recording BinaryWriter::recording(const std::string& bytes) {
  close_section();
  finished_ = true;
  if (bytes.size() != size_)
    throw Error("internal: a recording of " + std::to_string(bytes.size()) +
                " bytes from a writer that wrote " + std::to_string(size_));
  Recording r;
  for (std::size_t i = 0; i < sections_.size(); ++i) {
    const Section& s = sections_[i];
    const std::string marker_text = "§" + s.name;
    const std::size_t marker = sizeof(std::uint64_t) + marker_text.size();
    const bool is_marked = s.length >= marker &&
                           bytes.compare(s.offset + sizeof(std::uint64_t), marker_text.size(),
                                         marker_text) == 0;
    if (i == 0 && s.offset == 0 && !is_marked) {  // the bytes before the first marker
      r.header = bytes.substr(0, s.length);
      continue;
    }
    r.sections.emplace_back(s.name, bytes.substr(s.offset + marker, s.length - marker));
  }
  return r;
}

void BinaryWriter::replay(const Recording& r) {
  put(r.header.data(), r.header.size());
  for (const auto& [name, b] : r.sections) {
    section(name);
    put(b.data(), b.size());
  }
}

void BinaryReader::verify_checksums() {
  const std::streamoff start = in_.tellg();
  auto damaged = [&](const std::string& what) -> Error {
    in_.clear();
    return Error(source_ + ": " + what);
  };
  in_.seekg(0, std::ios::end);
  const std::streamoff size = in_.tellg();
  if (start < 0 || size < 0) throw damaged("cannot check the checksums: the stream cannot seek");
  const std::string no_table =
      "has no checksum table at its end: the file is truncated (a copy or a disk that ran full) "
      "or was not written completely; resume from another restart file or start the run again";
  if (size < static_cast<std::streamoff>(kFooterSize)) throw damaged(no_table);
  std::array<char, kFooterSize> footer{};
  in_.seekg(size - static_cast<std::streamoff>(kFooterSize));
  in_.read(footer.data(), static_cast<std::streamsize>(footer.size()));
  if (in_.gcount() != static_cast<std::streamsize>(footer.size()) ||
      std::memcmp(footer.data() + 12, kTrailer, sizeof(kTrailer)) != 0)
    throw damaged(no_table);
  std::uint64_t table_offset = 0;
  std::uint32_t table_crc = 0;
  std::memcpy(&table_offset, footer.data(), 8);
  std::memcpy(&table_crc, footer.data() + 8, 4);
  const auto table_end = static_cast<std::uint64_t>(size) - kFooterSize;
  if (table_offset > table_end) throw damaged("its checksum table is damaged (its position)");
  std::string table(table_end - table_offset, '\0');
  in_.seekg(static_cast<std::streamoff>(table_offset));
  in_.read(table.data(), static_cast<std::streamsize>(table.size()));
  if (static_cast<std::uint64_t>(in_.gcount()) != table.size() ||
      crc_update(0, table.data(), table.size()) != table_crc)
    throw damaged("its checksum table is damaged (CRC-32 of the table)");

  // Parse the table (already known to be intact): sections must tile [0, table_offset).
  std::size_t at = 0;
  auto take = [&](void* p, std::size_t n) {
    if (n > table.size() - at) throw damaged("its checksum table is damaged (its length)");
    std::memcpy(p, table.data() + at, n);
    at += n;
  };
  std::uint64_t count = 0;
  take(&count, 8);
  std::vector<char> buffer(std::size_t{1} << 20);
  std::uint64_t expected_offset = 0;
  table_.clear();
  for (std::uint64_t i = 0; i < count; ++i) {
    std::uint64_t name_size = 0, offset = 0, length = 0;
    std::uint32_t crc = 0;
    take(&name_size, 8);
    if (name_size > table.size() - at) throw damaged("its checksum table is damaged (a name)");
    std::string name(table.data() + at, name_size);
    at += name_size;
    take(&offset, 8);
    take(&length, 8);
    take(&crc, 4);
    if (offset != expected_offset || length > table_offset - offset)
      throw damaged("its checksum table is damaged (section '" + name + "' out of place)");
    expected_offset = offset + length;
    table_.emplace_back(name, static_cast<std::streamoff>(offset));
    in_.seekg(static_cast<std::streamoff>(offset));
    std::uint32_t sum = 0;
    for (std::uint64_t left = length; left > 0;) {
      const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(left, buffer.size()));
      in_.read(buffer.data(), static_cast<std::streamsize>(n));
      if (static_cast<std::size_t>(in_.gcount()) != n) throw damaged(no_table);
      sum = crc_update(sum, buffer.data(), n);
      left -= n;
    }
    if (sum != crc)
      throw damaged("section '" + name + "' (bytes " + std::to_string(offset) + " to " +
                    std::to_string(offset + length) +
                    ") is damaged: its CRC-32 differs from the one written with it, so the file "
                    "changed after it was written (a disk or copy error, or an edit); resume from "
                    "another restart file or start the run again");
  }
  if (expected_offset != table_offset || at != table.size())
    throw damaged("its checksum table is damaged (the sections do not cover the file)");
  in_.clear();
  in_.seekg(start);
  limit_ = static_cast<std::streamoff>(table_offset);
}

}  // namespace partita
