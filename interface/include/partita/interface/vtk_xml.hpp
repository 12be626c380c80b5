#pragma once
// The one VTK XML writer of partita: PolyData (.vtp: vertices and polygons) and UnstructuredGrid
// (.vtu: any VTK cell type), point and cell arrays of Float64, Float32, Int64, Int32 or UInt8
// with any number of components, in one of three encodings:
//   ascii   every value as text (shortest round-trip form: reads back bit for bit)
//   binary  appended raw: <AppendedData encoding="raw">_ then each array as a UInt64 byte count
//           and its bytes, back to back (header_type="UInt64")
//   zlib    appended, compressed as vtkZLibDataCompressor does: each array cut into blocks of
//           Options::block_size bytes, each block a zlib stream of its own; the array's header
//           is UInt64 [number of blocks, block size, size of the last partial block (0 if full),
//           compressed size of each block], followed by the compressed blocks. A block whose
//           first 4 KiB do not shrink by 10 % at the chosen level (random mantissas: positions,
//           velocities, forces gain about 5 %) is stored (deflate level 0), which reads the same
//           and costs a copy instead of the compressor's time (about 20x less).
// The bytes of an array are written straight from the caller's contiguous buffer (a view, no
// copy); vertex connectivity and offsets are generated as they are written. Files are written
// through AtomicFile: an error or an exception never leaves a half-written file.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace partita::vtk {

/// How the arrays are encoded (see the file comment).
enum class Format { ascii, binary, zlib };
/// Precision of the floating-point point and cell data arrays in the file.
enum class Precision { float64, float32 };

/// "ascii", "binary", "zlib".
std::string_view to_string(Format format);
/// The names of the formats: zlib, binary, ascii.
std::vector<std::string> format_names();
/// The format of that name; throws partita::Error listing the allowed names.
Format parse_format(std::string_view name);
/// "float64", "float32"; parse_precision() throws partita::Error listing them.
std::string_view to_string(Precision precision);
Precision parse_precision(std::string_view name);

struct Options {
  Format format = Format::zlib;
  int zlib_level = 1;                 ///< 1 (fastest) .. 9 (smallest)
  std::size_t block_size = 1u << 20;  ///< uncompressed bytes per zlib block (a multiple of 8)
  /// float32: Float64 point and cell data arrays are written as Float32 (converted while
  /// writing; the points and integer arrays are unchanged). Field values carry 7 significant
  /// digits, plenty to look at, and random mantissas do not compress: it is what makes a frame
  /// of 10^6 particles 3.5x smaller than the ASCII of old instead of 2.2x (bench/output).
  Precision precision = Precision::float32;
};

/// The element types of a data array (VTK's names).
enum class Type : std::uint8_t { Float64, Float32, Int64, Int32, UInt8 };

/// One named data array: tuples() x components() values, tuple after tuple. It views the
/// caller's buffer (which must outlive the write), owns a copy, or generates the sequence
/// first, first + step, ... (vertex connectivity and offsets).
class DataArray {
 public:
  DataArray() = default;

  /// A view of `tuples * components` values at `data` (double, float, int64, int32, uint8).
  template <class T>
  static DataArray view(std::string name, const T* data, std::size_t tuples, int components = 1) {
    DataArray a(std::move(name), type_of<T>(), tuples, components);
    a.data_ = data;
    return a;
  }
  /// An array that owns its values (`values.size()` a multiple of `components`).
  template <class T>
  static DataArray own(std::string name, std::vector<T> values, int components = 1) {
    auto held = std::make_shared<std::vector<T>>(std::move(values));
    DataArray a(std::move(name), type_of<T>(), held->size() / static_cast<std::size_t>(components),
                components);
    a.data_ = held->data();
    a.owned_ = std::move(held);
    return a;
  }
  /// The rows of an N x C matrix as N tuples (copied into tuple order). With
  /// `finite_or_zero`, non-finite entries are written as 0.
  static DataArray rows(std::string name, const Eigen::Ref<const Eigen::MatrixXd>& m,
                        bool finite_or_zero = false);
  /// Int64 values first + step * i, i = 0 .. count-1, generated while writing.
  static DataArray sequence(std::string name, std::size_t count, std::int64_t first,
                            std::int64_t step);

  const std::string& name() const { return name_; }
  Type type() const { return type_; }
  int components() const { return components_; }
  std::size_t tuples() const { return tuples_; }
  std::size_t values() const { return tuples_ * static_cast<std::size_t>(components_); }
  std::size_t bytes() const { return values() * type_size(type_); }
  bool empty() const { return tuples_ == 0; }

  /// The bytes of the array when it is stored (nullptr for a generated sequence).
  const std::byte* contiguous() const { return static_cast<const std::byte*>(data_); }
  /// Copy `length` bytes starting at byte `offset` of the array into `out`.
  void copy_bytes(std::size_t offset, std::size_t length, std::byte* out) const;
  /// Value k (0 .. values()-1) as the writer prints it.
  double real(std::size_t k) const;
  std::int64_t integer(std::size_t k) const;

  static std::size_t type_size(Type type);
  static const char* type_name(Type type);

 private:
  DataArray(std::string name, Type type, std::size_t tuples, int components)
      : name_(std::move(name)), type_(type), components_(components), tuples_(tuples) {}
  template <class T>
  static constexpr Type type_of() {
    if constexpr (std::is_same_v<T, double>)
      return Type::Float64;
    else if constexpr (std::is_same_v<T, float>)
      return Type::Float32;
    else if constexpr (std::is_same_v<T, std::int64_t>)
      return Type::Int64;
    else if constexpr (std::is_same_v<T, std::int32_t>)
      return Type::Int32;
    else {
      static_assert(std::is_same_v<T, std::uint8_t>,
                    "VTK arrays: double, float, int64, int32, "
                    "uint8");
      return Type::UInt8;
    }
  }

  std::string name_;
  Type type_ = Type::Float64;
  int components_ = 1;
  std::size_t tuples_ = 0;
  const void* data_ = nullptr;         // viewed or owned values; nullptr: a sequence
  std::shared_ptr<const void> owned_;  // keeps owned values alive
  std::int64_t first_ = 0, step_ = 0;  // the sequence
};

/// Cells of one kind as VTK stores them: connectivity (point indices, cell after cell) and
/// offsets (the end of each cell in connectivity); both integer arrays.
struct Cells {
  DataArray connectivity;
  DataArray offsets;
  std::size_t count() const { return offsets.tuples(); }

  /// One vertex cell per point 0 .. n-1 (particles, point clouds): generated, not stored.
  static Cells vertices(std::size_t n);
  /// Cells of `per_cell` points each (triangles: 3), `count * per_cell` indices at `indices`.
  static Cells uniform(const std::int32_t* indices, std::size_t count, int per_cell);
};

/// Attributes of a PointData or CellData element naming the active arrays, e.g.
/// {{"Scalars", "von_mises"}, {"Vectors", "displacement"}}.
using ActiveArrays = std::vector<std::pair<std::string, std::string>>;

/// A .vtp piece: points with vertex cells and/or polygons. Cell data: one tuple per vertex cell
/// then one per polygon (VTK's order).
struct PolyData {
  DataArray points;  ///< N x 3, Float64 or Float32
  Cells verts;
  Cells polys;
  std::vector<DataArray> point_data, cell_data;
  ActiveArrays point_active, cell_active;
};

/// A .vtu piece: points and cells of any VTK cell type.
struct UnstructuredGrid {
  DataArray points;  ///< N x 3, Float64 or Float32
  Cells cells;
  DataArray types;  ///< UInt8 VTK cell type per cell (VTK_TETRA = 10, VTK_HEXAHEDRON = 12, ...)
  std::vector<DataArray> point_data, cell_data;
  ActiveArrays point_active, cell_active;
};

/// Write the piece to `path` in the given format, atomically. Throws partita::Error naming the
/// file and the array when an array's length does not match the points or cells, or when the
/// file cannot be written.
void write(const std::filesystem::path& path, const PolyData& piece, const Options& options = {});
void write(const std::filesystem::path& path, const UnstructuredGrid& piece,
           const Options& options = {});

}  // namespace partita::vtk
