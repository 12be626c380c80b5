// The VTK XML writer: every format (ascii, appended raw, zlib blocks) holds exactly the values it
// was given, as VTK's own readers (python3-vtk9, those ParaView uses) read them back; bad input is
// refused with the file and the array named, and leaves no file behind.

#include "partita/interface/error.hpp"
#include "partita/interface/vtk_xml.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "../support/vtk_read.hpp"

namespace fs = std::filesystem;
using namespace partita;
using partita::test::read_vtk;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("partita_test_vtk_xml_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// Every format, the data arrays in their own precision (float64); then zlib level 9 with blocks
// of 1 KiB, so that arrays span many blocks.
std::vector<vtk::Options> every_format(vtk::Precision p = vtk::Precision::float64) {
  return {{vtk::Format::ascii, 1, 1u << 20, p},
          {vtk::Format::binary, 1, 1u << 20, p},
          {vtk::Format::zlib, 1, 1u << 20, p},
          {vtk::Format::zlib, 9, 1024, p}};
}

std::string describe(const vtk::Options& o) {
  return std::string(vtk::to_string(o.format)) + " level " + std::to_string(o.zlib_level) +
         " block " + std::to_string(o.block_size) + " " + std::string(vtk::to_string(o.precision));
}

// Values that a text format with too few digits or a wrong byte count would change.
std::vector<double> awkward_doubles(std::size_t n) {
  const std::vector<double> special = {0.1,
                                       1.0 / 3.0,
                                       -2.0 / 7.0,
                                       1e-300,
                                       6.02214076e23,
                                       std::numeric_limits<double>::max(),
                                       std::numeric_limits<double>::denorm_min(),
                                       -0.0,
                                       0.0,
                                       std::nextafter(1.0, 2.0)};
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i)
    v[i] = i < special.size() ? special[i] : std::sin(0.37 * static_cast<double>(i)) * 1e-3;
  return v;
}

}  // namespace

TEST_CASE("vtk xml: every format holds the given values as VTK reads them (PolyData)",
          "[interface][output][vtk]") {
  const fs::path dir = scratch("polydata");
  // 700 points as vertex cells, then 300 triangles: cell data covers both (verts first)
  const std::size_t n = 700, nt = 300;
  const std::vector<double> xyz = awkward_doubles(3 * n);
  std::vector<std::int32_t> tri(3 * nt);
  for (std::size_t k = 0; k < tri.size(); ++k) tri[k] = static_cast<std::int32_t>((k * 13) % n);
  std::vector<float> f(n);
  std::vector<std::int64_t> id(n);
  std::vector<std::uint8_t> flag(n + nt);
  std::vector<std::int32_t> cell_int(n + nt);
  for (std::size_t i = 0; i < n; ++i) {
    f[i] = static_cast<float>(1.0 / (1.0 + static_cast<double>(i)));
    id[i] = (std::int64_t{1} << 62) + static_cast<std::int64_t>(i) * 7 - 3;  // beyond 2^53
  }
  for (std::size_t c = 0; c < n + nt; ++c) {
    flag[c] = static_cast<std::uint8_t>(c % 256);
    cell_int[c] = -static_cast<std::int32_t>(c);
  }
  vtk::PolyData piece;
  piece.points = vtk::DataArray::view("Points", xyz.data(), n, 3);
  piece.verts = vtk::Cells::vertices(n);
  piece.polys = vtk::Cells::uniform(tri.data(), nt, 3);
  piece.point_data = {vtk::DataArray::view("velocity", xyz.data(), n, 3),
                      vtk::DataArray::view("single", f.data(), n),
                      vtk::DataArray::view("id&<name>", id.data(), n)};
  piece.cell_data = {vtk::DataArray::view("flag", flag.data(), n + nt),
                     vtk::DataArray::view("minus", cell_int.data(), n + nt)};
  piece.point_active = {{"Vectors", "velocity"}};

  std::string first;
  for (const vtk::Options& o : every_format()) {
    {
      INFO(describe(o));
      const fs::path file = dir / ("p_" + describe(o) + ".vtp");
      vtk::write(file, piece, o);
      CHECK_FALSE(fs::exists(file.string() + ".part"));
      const auto c = read_vtk(file);
      INFO(c.text.substr(0, 2000));
      REQUIRE(c.ok);
      REQUIRE(c.points == n);
      REQUIRE(c.xyz.size() == xyz.size());
      for (std::size_t k = 0; k < xyz.size(); ++k) {
        INFO("coordinate " << k);
        CHECK(c.xyz[k] == xyz[k]);
        CHECK(std::signbit(c.xyz[k]) == std::signbit(xyz[k]));  // -0.0 stays -0.0
      }
      const auto& v = c.cells.at("verts");
      REQUIRE(v.count == n);
      for (std::size_t i = 0; i < n; ++i) {
        CHECK(v.connectivity[i] == static_cast<std::int64_t>(i));
        CHECK(v.offsets[i + 1] == static_cast<std::int64_t>(i + 1));  // VTK's offsets start at 0
      }
      const auto& p = c.cells.at("polys");
      REQUIRE(p.count == nt);
      REQUIRE(p.connectivity.size() == tri.size());
      for (std::size_t k = 0; k < tri.size(); ++k) CHECK(p.connectivity[k] == tri[k]);
      REQUIRE(c.point.count("velocity") == 1);
      CHECK(c.point.at("velocity").components == 3);
      CHECK(c.point.at("velocity").values == xyz);
      REQUIRE(c.point.at("single").type == "float");
      for (std::size_t i = 0; i < n; ++i)
        CHECK(static_cast<float>(c.point.at("single").values[i]) == f[i]);
      CHECK(c.point.at("id&<name>").ints == id);  // Int64 beyond 2^53, as integers
      CHECK(c.cell.at("flag").ints == std::vector<std::int64_t>(flag.begin(), flag.end()));
      CHECK(c.cell.at("minus").ints == std::vector<std::int64_t>(cell_int.begin(), cell_int.end()));
      CHECK(c.active.at("point Vectors") == "velocity");
    }
  }
  for (const vtk::Options& o : every_format()) {  // every format: the same content
    const auto c = read_vtk(dir / ("p_" + describe(o) + ".vtp"));
    if (first.empty()) first = c.text;
    CHECK(c.text == first);
  }
}

TEST_CASE("vtk xml: every format holds the given values as VTK reads them (UnstructuredGrid)",
          "[interface][output][vtk]") {
  const fs::path dir = scratch("ugrid");
  // a tetrahedron (VTK_TETRA 10), a hexahedron (12), a triangle (5) and a vertex (1)
  const std::vector<double> xyz = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,
                                   0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  const std::vector<std::int64_t> conn = {0, 1, 3, 4, 0, 1, 2, 3, 4, 5, 6, 7, 4, 5, 6, 7};
  const std::vector<std::int64_t> offsets = {4, 12, 15, 16};
  const std::vector<std::uint8_t> types = {10, 12, 5, 1};
  const std::vector<double> stress = awkward_doubles(8 * 6);
  const std::vector<std::int32_t> region = {3, -1, 0, 7};
  vtk::UnstructuredGrid piece;
  piece.points = vtk::DataArray::view("Points", xyz.data(), 8, 3);
  piece.cells = {vtk::DataArray::view("connectivity", conn.data(), conn.size()),
                 vtk::DataArray::view("offsets", offsets.data(), offsets.size())};
  piece.types = vtk::DataArray::view("types", types.data(), types.size());
  piece.point_data = {vtk::DataArray::view("stress", stress.data(), 8, 6)};
  piece.cell_data = {vtk::DataArray::view("region", region.data(), 4)};
  piece.point_active = {{"Tensors", "stress"}};
  std::string first;
  for (const vtk::Options& o : every_format()) {
    INFO(describe(o));
    const fs::path file = dir / ("u_" + describe(o) + ".vtu");
    vtk::write(file, piece, o);
    const auto c = read_vtk(file);
    INFO(c.text);
    REQUIRE(c.ok);
    CHECK(c.xyz == xyz);
    CHECK(c.types == std::vector<std::int64_t>(types.begin(), types.end()));
    CHECK(c.cells.at("cells").connectivity == conn);
    CHECK(c.cells.at("cells").offsets == std::vector<std::int64_t>({0, 4, 12, 15, 16}));
    CHECK(c.point.at("stress").components == 6);
    CHECK(c.point.at("stress").values == stress);
    CHECK(c.cell.at("region").ints == std::vector<std::int64_t>(region.begin(), region.end()));
    if (first.empty()) first = c.text;
    CHECK(c.text == first);
  }
}

TEST_CASE("vtk xml: an empty piece and an array of exactly whole zlib blocks open in VTK",
          "[interface][output][vtk]") {
  const fs::path dir = scratch("edge");
  for (const vtk::Options& o : every_format(vtk::Precision::float32)) {
    INFO(describe(o));
    vtk::PolyData empty;
    empty.points = vtk::DataArray::view<double>("Points", nullptr, 0, 3);
    empty.verts = vtk::Cells::vertices(0);
    empty.point_data = {vtk::DataArray::view<double>("radius", nullptr, 0)};
    const fs::path file = dir / ("empty_" + describe(o) + ".vtp");
    vtk::write(file, empty, o);
    const auto c = read_vtk(file);
    INFO(c.text);
    CHECK(c.ok);
    CHECK(c.points == 0);
  }
  // 3 x 1024 bytes of coordinates with 1 KiB blocks: the last block is full (header entry 0)
  std::vector<double> xyz(384);
  for (std::size_t k = 0; k < xyz.size(); ++k) xyz[k] = 0.25 * static_cast<double>(k);
  vtk::PolyData piece;
  piece.points = vtk::DataArray::view("Points", xyz.data(), 128, 3);
  piece.verts = vtk::Cells::vertices(128);
  const fs::path file = dir / "whole_blocks.vtp";
  vtk::write(file, piece, {vtk::Format::zlib, 1, 1024, vtk::Precision::float64});
  const auto c = read_vtk(file);
  INFO(c.text);
  REQUIRE(c.ok);
  CHECK(c.xyz == xyz);
}

TEST_CASE("vtk xml: a raw binary file has exactly the bytes of its arrays and their headers",
          "[interface][output][vtk]") {
  // appended raw: each array is an 8-byte count followed by its bytes, nothing else
  const fs::path dir = scratch("size");
  const std::size_t n = 100000;
  std::vector<double> xyz(3 * n, 0.5);
  vtk::PolyData piece;
  piece.points = vtk::DataArray::view("Points", xyz.data(), n, 3);
  piece.verts = vtk::Cells::vertices(n);
  piece.point_data = {vtk::DataArray::view("radius", xyz.data(), n)};
  vtk::write(dir / "p.vtp", piece, {vtk::Format::binary, 1, 1u << 20, vtk::Precision::float64});
  const std::size_t payload = (8 + 24 * n) + (8 + 8 * n) + (8 + 8 * n) + (8 + 8 * n);
  const auto size = fs::file_size(dir / "p.vtp");
  CHECK(size > payload);
  CHECK(size < payload + 2000);  // the XML text around it
  // float32: the radius (a data array) takes 4 bytes a value, the points keep 8
  vtk::write(dir / "p32.vtp", piece, {vtk::Format::binary});
  CHECK(size - fs::file_size(dir / "p32.vtp") == 4 * n);
  vtk::write(dir / "z.vtp", piece, {vtk::Format::zlib});
  CHECK(fs::file_size(dir / "z.vtp") < size / 10);
}

TEST_CASE("vtk xml: bad input is refused with the file and the array named, no file is left",
          "[interface][output][vtk]") {
  const fs::path dir = scratch("bad");
  const std::vector<double> xyz(30, 1.0);
  const std::vector<double> short_array(9, 1.0);
  vtk::PolyData piece;
  piece.points = vtk::DataArray::view("Points", xyz.data(), 10, 3);
  piece.verts = vtk::Cells::vertices(10);
  piece.point_data = {vtk::DataArray::view("radius", short_array.data(), 9)};
  const fs::path file = dir / "p.vtp";
  CHECK_THROWS_WITH(vtk::write(file, piece), Catch::Contains("p.vtp") &&
                                                 Catch::Contains("point array 'radius' has 9") &&
                                                 Catch::Contains("expected 10"));
  piece.point_data.clear();
  piece.cell_data = {vtk::DataArray::view("force", xyz.data(), 10, 3)};
  std::vector<std::int32_t> tri = {0, 1, 2};
  piece.polys = vtk::Cells::uniform(tri.data(), 1, 3);
  CHECK_THROWS_WITH(vtk::write(file, piece),
                    Catch::Contains("cell array 'force' has 10") && Catch::Contains("expected 11"));
  piece.cell_data.clear();
  CHECK_THROWS_WITH(vtk::write(file, piece, {vtk::Format::zlib, 0}),
                    Catch::Contains("zlib level 0 is not in 1 .. 9"));
  CHECK_FALSE(fs::exists(file));
  CHECK_FALSE(fs::exists(file.string() + ".part"));
  std::ofstream(dir / "a_file") << "x";
  CHECK_THROWS_AS(vtk::write(dir / "a_file" / "p.vtp", piece), Error);  // cannot be created
  vtk::write(file, piece);                                              // now valid
  CHECK(read_vtk(file).ok);
  // a failed rewrite leaves the complete earlier file in place
  const auto before = fs::file_size(file);
  piece.point_data = {vtk::DataArray::view("radius", short_array.data(), 9)};
  CHECK_THROWS_AS(vtk::write(file, piece), Error);
  CHECK(fs::file_size(file) == before);
  CHECK(vtk::parse_format("binary") == vtk::Format::binary);
  CHECK_THROWS_WITH(vtk::parse_format("gzip"), Catch::Contains("allowed: zlib, binary, ascii"));
}

TEST_CASE("vtk xml: float32 precision writes the data arrays as Float32, coordinates exactly",
          "[interface][output][vtk]") {
  const fs::path dir = scratch("float32");
  const std::size_t n = 3000;
  const std::vector<double> xyz = awkward_doubles(3 * n);
  std::vector<double> field(n);
  std::vector<std::int64_t> id(n);
  for (std::size_t i = 0; i < n; ++i) {
    field[i] = 1.0 / (3.0 + static_cast<double>(i));  // not a float: rounded to one
    id[i] = (std::int64_t{1} << 60) + static_cast<std::int64_t>(i);
  }
  vtk::PolyData piece;
  piece.points = vtk::DataArray::view("Points", xyz.data(), n, 3);
  piece.verts = vtk::Cells::vertices(n);
  piece.point_data = {vtk::DataArray::view("field", field.data(), n),
                      vtk::DataArray::view("id", id.data(), n)};
  std::string first;
  for (const vtk::Options& o : every_format(vtk::Precision::float32)) {
    INFO(describe(o));
    const fs::path file = dir / ("p_" + describe(o) + ".vtp");
    vtk::write(file, piece, o);
    const auto c = read_vtk(file);
    INFO(c.text.substr(0, 1000));
    REQUIRE(c.ok);
    CHECK(c.xyz == xyz);  // the points keep their precision
    REQUIRE(c.point.at("field").type == "float");
    for (std::size_t i = 0; i < n; ++i)
      CHECK(c.point.at("field").values[i] == static_cast<double>(static_cast<float>(field[i])));
    CHECK(c.point.at("id").ints == id);
    if (first.empty()) first = c.text;
    CHECK(c.text == first);
  }
}
