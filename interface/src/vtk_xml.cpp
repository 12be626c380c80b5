#include "partita/interface/vtk_xml.hpp"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <ostream>

#include "partita/interface/error.hpp"
#include "partita/interface/output.hpp"

namespace partita::vtk {

// ---------------------------------------------------------------------------------------------
// Formats

std::string_view to_string(Format format) {
  switch (format) {
    case Format::ascii:
      return "ascii";
    case Format::binary:
      return "binary";
    case Format::zlib:
      return "zlib";
  }
  return "?";
}

std::vector<std::string> format_names() {
  std::vector<std::string> names;
  for (Format f : {Format::zlib, Format::binary, Format::ascii}) names.emplace_back(to_string(f));
  return names;
}

Format parse_format(std::string_view name) {
  for (Format f : {Format::zlib, Format::binary, Format::ascii})
    if (to_string(f) == name) return f;
  throw Error("unknown VTK format '" + std::string(name) + "'; allowed: zlib, binary, ascii");
}

std::string_view to_string(Precision precision) {
  return precision == Precision::float32 ? "float32" : "float64";
}

Precision parse_precision(std::string_view name) {
  for (Precision p : {Precision::float64, Precision::float32})
    if (to_string(p) == name) return p;
  throw Error("unknown VTK precision '" + std::string(name) + "'; allowed: float64, float32");
}

// ---------------------------------------------------------------------------------------------
// DataArray

std::size_t DataArray::type_size(Type type) {
  switch (type) {
    case Type::Float64:
    case Type::Int64:
      return 8;
    case Type::Float32:
    case Type::Int32:
      return 4;
    case Type::UInt8:
      return 1;
  }
  return 0;
}

const char* DataArray::type_name(Type type) {
  switch (type) {
    case Type::Float64:
      return "Float64";
    case Type::Float32:
      return "Float32";
    case Type::Int64:
      return "Int64";
    case Type::Int32:
      return "Int32";
    case Type::UInt8:
      return "UInt8";
  }
  return "?";
}

DataArray DataArray::rows(std::string name, const Eigen::Ref<const Eigen::MatrixXd>& m,
                          bool finite_or_zero) {
  std::vector<double> v(static_cast<std::size_t>(m.size()));
  std::size_t k = 0;
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index c = 0; c < m.cols(); ++c, ++k)
      v[k] = (finite_or_zero && !std::isfinite(m(i, c))) ? 0.0 : m(i, c);
  DataArray a =
      own(std::move(name), std::move(v), static_cast<int>(std::max<Eigen::Index>(1, m.cols())));
  a.tuples_ = static_cast<std::size_t>(m.rows());
  return a;
}

DataArray DataArray::sequence(std::string name, std::size_t count, std::int64_t first,
                              std::int64_t step) {
  DataArray a(std::move(name), Type::Int64, count, 1);
  a.first_ = first;
  a.step_ = step;
  return a;
}

void DataArray::copy_bytes(std::size_t offset, std::size_t length, std::byte* out) const {
  if (data_) {
    std::memcpy(out, contiguous() + offset, length);
    return;
  }
  // a sequence: generate the int64 values that cover [offset, offset + length)
  std::size_t k = offset / 8, skip = offset % 8;
  while (length > 0) {
    const std::int64_t v = first_ + step_ * static_cast<std::int64_t>(k);
    std::array<std::byte, 8> b;
    std::memcpy(b.data(), &v, 8);
    const std::size_t n = std::min<std::size_t>(8 - skip, length);
    std::memcpy(out, b.data() + skip, n);
    out += n;
    length -= n;
    skip = 0;
    ++k;
  }
}

double DataArray::real(std::size_t k) const {
  switch (type_) {
    case Type::Float64:
      return static_cast<const double*>(data_)[k];
    case Type::Float32:
      return static_cast<const float*>(data_)[k];
    default:
      return static_cast<double>(integer(k));
  }
}

std::int64_t DataArray::integer(std::size_t k) const {
  if (!data_) return first_ + step_ * static_cast<std::int64_t>(k);
  switch (type_) {
    case Type::Int64:
      return static_cast<const std::int64_t*>(data_)[k];
    case Type::Int32:
      return static_cast<const std::int32_t*>(data_)[k];
    case Type::UInt8:
      return static_cast<const std::uint8_t*>(data_)[k];
    default:
      return static_cast<std::int64_t>(real(k));
  }
}

// ---------------------------------------------------------------------------------------------
// Cells

Cells Cells::vertices(std::size_t n) {
  return {DataArray::sequence("connectivity", n, 0, 1), DataArray::sequence("offsets", n, 1, 1)};
}

Cells Cells::uniform(const std::int32_t* indices, std::size_t count, int per_cell) {
  return {DataArray::view("connectivity", indices, count * static_cast<std::size_t>(per_cell)),
          DataArray::sequence("offsets", count, per_cell, per_cell)};
}

// ---------------------------------------------------------------------------------------------
// Writing

namespace {

constexpr const char* kByteOrder =
    std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian";
constexpr std::size_t kChunk = 1u << 16;  // bytes of a generated array written at a time
constexpr int kOffsetField = 21;          // digits of an offset and its closing quote

std::string escape(const std::string& s) {
  std::string r;
  for (char c : s) {
    switch (c) {
      case '&':
        r += "&amp;";
        break;
      case '<':
        r += "&lt;";
        break;
      case '>':
        r += "&gt;";
        break;
      case '"':
        r += "&quot;";
        break;
      default:
        r += c;
    }
  }
  return r;
}

// An array as it goes into the file: its own bytes, or its Float64 values as Float32.
struct Encoded {
  const DataArray* array = nullptr;
  bool to_float32 = false;

  Type type() const { return to_float32 ? Type::Float32 : array->type(); }
  std::size_t bytes() const { return array->values() * DataArray::type_size(type()); }
  const std::byte* contiguous() const { return to_float32 ? nullptr : array->contiguous(); }
  // `offset` and `length` are multiples of 4 when converting
  void copy(std::size_t offset, std::size_t length, std::byte* out) const {
    if (!to_float32) {
      array->copy_bytes(offset, length, out);
      return;
    }
    const double* d = reinterpret_cast<const double*>(array->contiguous()) + offset / 4;
    for (std::size_t k = 0; k < length / 4; ++k) {
      const auto f = static_cast<float>(d[k]);
      std::memcpy(out + 4 * k, &f, 4);
    }
  }
};

// ASCII values: one tuple per line, the shortest text that reads back to the same value.
class AsciiValues {
 public:
  explicit AsciiValues(std::ostream& out) : out_(out) { text_.reserve(kBuffer + 64); }

  void write(const Encoded& e) {
    const DataArray& a = *e.array;
    const std::size_t per = static_cast<std::size_t>(a.components());
    const std::byte* p = a.contiguous();
    for (std::size_t t = 0; t < a.tuples(); ++t) {
      text_ += "          ";
      for (std::size_t c = 0; c < per; ++c) {
        const std::size_t k = t * per + c;
        char buf[32];
        std::to_chars_result r{};
        switch (p ? a.type() : Type::Int64) {
          case Type::Float64:
            if (e.to_float32)
              r = std::to_chars(buf, buf + sizeof buf,
                                static_cast<float>(reinterpret_cast<const double*>(p)[k]));
            else
              r = std::to_chars(buf, buf + sizeof buf, reinterpret_cast<const double*>(p)[k]);
            break;
          case Type::Float32:
            r = std::to_chars(buf, buf + sizeof buf, reinterpret_cast<const float*>(p)[k]);
            break;
          default:
            r = std::to_chars(buf, buf + sizeof buf, a.integer(k));
        }
        text_.append(buf, r.ptr);
        text_ += c + 1 < per ? ' ' : '\n';
      }
      if (text_.size() > kBuffer) flush();
    }
    flush();
  }

 private:
  static constexpr std::size_t kBuffer = 1u << 20;
  void flush() {
    out_.write(text_.data(), static_cast<std::streamsize>(text_.size()));
    text_.clear();
  }
  std::ostream& out_;
  std::string text_;
};

// zlib streams of one block each, from two reused deflate streams: the chosen level, and level
// 0 (stored) for blocks that do not compress.
class Deflater {
 public:
  Deflater(int level, std::size_t block) {
    if (deflateInit(&level_, level) != Z_OK || deflateInit(&stored_, 0) != Z_OK)
      throw Error("VTK output: zlib initialisation failed");
    out_.resize(std::max(deflateBound(&level_, static_cast<uLong>(block)),
                         deflateBound(&stored_, static_cast<uLong>(block))));
    in_.resize(block);
  }
  ~Deflater() {
    deflateEnd(&level_);
    deflateEnd(&stored_);
  }
  Deflater(const Deflater&) = delete;
  Deflater& operator=(const Deflater&) = delete;

  /// Compress `length` bytes at `data`; returns the compressed bytes (valid until the next call).
  std::pair<const unsigned char*, std::size_t> block(const std::byte* data, std::size_t length) {
    z_stream* z = &level_;
    if (length >= 2 * kProbe) {  // does the start of the block compress by 10 %?
      const std::size_t probe = run(level_, data, kProbe);
      if (10 * probe > 9 * kProbe) z = &stored_;
    }
    return {out_.data(), run(*z, data, length)};
  }
  std::byte* input() { return in_.data(); }

 private:
  static constexpr std::size_t kProbe = 4096;
  std::size_t run(z_stream& zs, const std::byte* data, std::size_t length) {
    deflateReset(&zs);
    zs.next_in = reinterpret_cast<Bytef*>(const_cast<std::byte*>(data));
    zs.avail_in = static_cast<uInt>(length);
    zs.next_out = out_.data();
    zs.avail_out = static_cast<uInt>(out_.size());
    if (deflate(&zs, Z_FINISH) != Z_STREAM_END) throw Error("VTK output: zlib compression failed");
    return out_.size() - zs.avail_out;
  }
  z_stream level_{}, stored_{};
  std::vector<unsigned char> out_;
  std::vector<std::byte> in_;
};

class XmlWriter {
 public:
  XmlWriter(const std::filesystem::path& path, const Options& options, const char* type)
      : file_(path, true), out_(file_.stream()), options_(options) {
    if (options.format == Format::zlib) {
      if (options.zlib_level < 1 || options.zlib_level > 9)
        throw Error("VTK output '" + path.string() + "': zlib level " +
                    std::to_string(options.zlib_level) + " is not in 1 .. 9");
      if (options.block_size < 1024 || options.block_size > (1u << 30) ||
          options.block_size % 8 != 0)
        throw Error("VTK output '" + path.string() + "': zlib block size " +
                    std::to_string(options.block_size) +
                    " is not a multiple of 8 in 1 KiB .. 1 GiB");
    }
    out_ << "<?xml version=\"1.0\"?>\n<VTKFile type=\"" << type
         << "\" version=\"1.0\" byte_order=\"" << kByteOrder << "\" header_type=\"UInt64\"";
    if (options.format == Format::zlib) out_ << " compressor=\"vtkZLibDataCompressor\"";
    out_ << ">\n  <" << type << ">\n";
  }

  std::ostream& out() { return out_; }

  // `data`: a point or cell data array (written as Float32 if the options say so)
  void array(const DataArray& a, const char* indent, bool data = false) {
    const Encoded e{&a,
                    data && a.type() == Type::Float64 && options_.precision == Precision::float32};
    out_ << indent << "<DataArray type=\"" << DataArray::type_name(e.type()) << '"';
    if (!a.name().empty()) out_ << " Name=\"" << escape(a.name()) << '"';
    out_ << " NumberOfComponents=\"" << a.components() << "\" format=\""
         << (options_.format == Format::ascii ? "ascii" : "appended") << '"';
    if (options_.format == Format::ascii) {
      out_ << ">\n";
      AsciiValues(out_).write(e);
      out_ << indent << "</DataArray>\n";
      return;
    }
    out_ << " offset=\"";
    patch_.push_back(out_.tellp());
    out_ << std::string(kOffsetField, ' ') << "/>\n";
    appended_.push_back(e);
  }

  void data(const char* tag, const std::vector<DataArray>& arrays, const ActiveArrays& active) {
    out_ << "      <" << tag;
    for (const auto& [k, v] : active) out_ << ' ' << k << "=\"" << escape(v) << '"';
    out_ << ">\n";
    for (const DataArray& a : arrays) array(a, "        ", true);
    out_ << "      </" << tag << ">\n";
  }

  void finish(const char* type) {
    out_ << "    </Piece>\n  </" << type << ">\n";
    std::vector<std::uint64_t> offsets;
    if (options_.format != Format::ascii) {
      out_ << "  <AppendedData encoding=\"raw\">\n   _";
      const auto base = out_.tellp();
      std::unique_ptr<Deflater> z;
      if (options_.format == Format::zlib)
        z = std::make_unique<Deflater>(options_.zlib_level, options_.block_size);
      for (const Encoded& e : appended_) {
        offsets.push_back(static_cast<std::uint64_t>(out_.tellp() - base));
        if (z)
          compressed(e, *z);
        else
          raw(e);
      }
      out_ << "\n  </AppendedData>\n";
    }
    out_ << "</VTKFile>\n";
    for (std::size_t k = 0; k < offsets.size(); ++k) {
      out_.seekp(patch_[k]);
      out_ << offsets[k] << '"';
    }
    file_.commit();
  }

 private:
  void put64(std::uint64_t v) { out_.write(reinterpret_cast<const char*>(&v), 8); }

  // header: the byte count; then the bytes
  void raw(const Encoded& a) {
    put64(a.bytes());
    if (const std::byte* p = a.contiguous()) {
      out_.write(reinterpret_cast<const char*>(p), static_cast<std::streamsize>(a.bytes()));
      return;
    }
    std::array<std::byte, kChunk> chunk;
    for (std::size_t at = 0; at < a.bytes(); at += kChunk) {
      const std::size_t n = std::min(kChunk, a.bytes() - at);
      a.copy(at, n, chunk.data());
      out_.write(reinterpret_cast<const char*>(chunk.data()), static_cast<std::streamsize>(n));
    }
  }

  // header: blocks, block size, last partial block size, compressed size of each block; then
  // the compressed blocks (the header is written again once the sizes are known)
  void compressed(const Encoded& a, Deflater& z) {
    const std::size_t total = a.bytes(), bs = options_.block_size;
    const std::size_t blocks = total / bs + (total % bs ? 1 : 0);
    std::vector<std::uint64_t> header(3 + blocks, 0);
    header[0] = blocks;
    header[1] = bs;
    header[2] = total % bs;
    const auto at = out_.tellp();
    out_.write(reinterpret_cast<const char*>(header.data()),
               static_cast<std::streamsize>(8 * header.size()));
    for (std::size_t b = 0; b < blocks; ++b) {
      const std::size_t n = std::min(bs, total - b * bs);
      const std::byte* in = a.contiguous() ? a.contiguous() + b * bs : nullptr;
      if (!in) {
        a.copy(b * bs, n, z.input());
        in = z.input();
      }
      const auto [c, size] = z.block(in, n);
      header[3 + b] = size;
      out_.write(reinterpret_cast<const char*>(c), static_cast<std::streamsize>(size));
    }
    const auto end = out_.tellp();
    out_.seekp(at);
    out_.write(reinterpret_cast<const char*>(header.data()),
               static_cast<std::streamsize>(8 * header.size()));
    out_.seekp(end);
  }

  AtomicFile file_;
  std::ostream& out_;
  Options options_;
  std::vector<std::streampos> patch_;
  std::vector<Encoded> appended_;
};

[[noreturn]] void wrong_length(const std::filesystem::path& path, const std::string& what,
                               const DataArray& a, std::size_t expected, const char* of) {
  throw Error("VTK output '" + path.string() + "': " + what + " array '" + a.name() + "' has " +
              std::to_string(a.tuples()) + " tuples, expected " + std::to_string(expected) +
              " (one per " + of + ")");
}

void check_points(const std::filesystem::path& path, const DataArray& p) {
  if ((p.components() != 3 && !p.empty()) ||
      (p.type() != Type::Float64 && p.type() != Type::Float32))
    throw Error("VTK output '" + path.string() + "': the points must be Float64 or Float32 x 3, " +
                "not " + DataArray::type_name(p.type()) + " x " + std::to_string(p.components()));
}

void check_cells(const std::filesystem::path& path, const char* kind, const Cells& c) {
  if (c.count() == 0 && c.connectivity.empty()) return;  // none of this kind
  for (const DataArray* a : {&c.connectivity, &c.offsets})
    if ((a->type() != Type::Int64 && a->type() != Type::Int32) || a->components() != 1)
      throw Error("VTK output '" + path.string() + "': " + kind + " " + a->name() +
                  " must be one Int64 or Int32 per entry");
  if (c.count() > 0 &&
      static_cast<std::size_t>(c.offsets.integer(c.count() - 1)) != c.connectivity.values())
    throw Error("VTK output '" + path.string() + "': " + kind + ": the last offset is " +
                std::to_string(c.offsets.integer(c.count() - 1)) + ", the connectivity has " +
                std::to_string(c.connectivity.values()) + " entries");
}

void check_data(const std::filesystem::path& path, const std::vector<DataArray>& arrays,
                std::size_t count, const char* where, const char* of) {
  for (const DataArray& a : arrays)
    if (a.tuples() != count) wrong_length(path, where, a, count, of);
}

}  // namespace

void write(const std::filesystem::path& path, const PolyData& piece, const Options& options) {
  const std::size_t np = piece.points.tuples();
  const std::size_t nv = piece.verts.count(), npoly = piece.polys.count();
  check_points(path, piece.points);
  check_cells(path, "Verts", piece.verts);
  check_cells(path, "Polys", piece.polys);
  check_data(path, piece.point_data, np, "point", "point");
  check_data(path, piece.cell_data, nv + npoly, "cell", "cell");
  XmlWriter w(path, options, "PolyData");
  w.out() << "    <Piece NumberOfPoints=\"" << np << "\" NumberOfVerts=\"" << nv
          << "\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"" << npoly << "\">\n";
  w.data("PointData", piece.point_data, piece.point_active);
  w.data("CellData", piece.cell_data, piece.cell_active);
  w.out() << "      <Points>\n";
  w.array(piece.points, "        ");
  w.out() << "      </Points>\n";
  for (const auto& [tag, cells] : {std::pair{"Verts", &piece.verts}, {"Polys", &piece.polys}}) {
    if (cells->count() == 0) continue;
    w.out() << "      <" << tag << ">\n";
    w.array(cells->connectivity, "        ");
    w.array(cells->offsets, "        ");
    w.out() << "      </" << tag << ">\n";
  }
  w.finish("PolyData");
}

void write(const std::filesystem::path& path, const UnstructuredGrid& piece,
           const Options& options) {
  const std::size_t np = piece.points.tuples(), nc = piece.cells.count();
  check_points(path, piece.points);
  check_cells(path, "Cells", piece.cells);
  if (piece.types.type() != Type::UInt8 || piece.types.tuples() != nc)
    throw Error("VTK output '" + path.string() + "': the cell types must be one UInt8 per cell");
  check_data(path, piece.point_data, np, "point", "point");
  check_data(path, piece.cell_data, nc, "cell", "cell");
  XmlWriter w(path, options, "UnstructuredGrid");
  w.out() << "    <Piece NumberOfPoints=\"" << np << "\" NumberOfCells=\"" << nc << "\">\n";
  w.data("PointData", piece.point_data, piece.point_active);
  w.data("CellData", piece.cell_data, piece.cell_active);
  w.out() << "      <Points>\n";
  w.array(piece.points, "        ");
  w.out() << "      </Points>\n      <Cells>\n";
  w.array(piece.cells.connectivity, "        ");
  w.array(piece.cells.offsets, "        ");
  w.array(piece.types, "        ");
  w.out() << "      </Cells>\n";
  w.finish("UnstructuredGrid");
}

}  // namespace partita::vtk
