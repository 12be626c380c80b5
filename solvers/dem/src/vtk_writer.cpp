#include "partita/dem/vtk_writer.hpp"

#include "partita/dem/error.hpp"

#include <charconv>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

namespace partita::dem {

namespace {

// A double as text with `digits` significant digits (std::to_chars: several times faster than
// an ostream's formatting, which dominated the output time).
void put_number(std::ostream& out, double v, int digits) {
  char buf[40];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, digits);
  out.write(buf, r.ptr - buf);
}

void write_arrays(std::ostream& out, const char* tag, const std::vector<VtkArray>& arrays,
                  std::size_t count, const std::string& path) {
  out << "      <" << tag << ">\n";
  for (const VtkArray& a : arrays) {
    if (a.values.size() != count * a.components) {
      std::ostringstream msg;
      msg << "VTK output " << path << ": array '" << a.name << "' has " << a.values.size()
          << " values, expected " << count * a.components;
      throw Error(msg.str());
    }
    out << "        <DataArray type=\"" << (a.integer ? "Int64" : "Float64") << "\" Name=\""
        << a.name << "\" NumberOfComponents=\"" << a.components << "\" format=\"ascii\">\n";
    for (std::size_t k = 0; k < a.values.size(); ++k) {
      if (a.integer)
        out << static_cast<std::int64_t>(a.values[k]);
      else
        put_number(out, a.values[k], 12);
      out << ((k + 1) % a.components == 0 ? '\n' : ' ');
    }
    out << "        </DataArray>\n";
  }
  out << "      </" << tag << ">\n";
}

void write_points_array(std::ostream& out, const std::vector<Eigen::Vector3d>& points) {
  out << "      <Points>\n        <DataArray type=\"Float64\" NumberOfComponents=\"3\" "
         "format=\"ascii\">\n";
  for (const Eigen::Vector3d& x : points) {
    put_number(out, x.x(), 12);
    out << ' ';
    put_number(out, x.y(), 12);
    out << ' ';
    put_number(out, x.z(), 12);
    out << '\n';
  }
  out << "        </DataArray>\n      </Points>\n";
}

// Writes through a temporary file next to the target, then renames it into place.
template <class Body>
void write_atomically(const std::string& path, Body&& body) {
  const std::filesystem::path target(path);
  const std::filesystem::path tmp = target.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw Error("VTK output: cannot open " + tmp.string() + " for writing");
    out.precision(12);
    body(out);
    out.flush();
    if (!out) throw Error("VTK output: writing " + tmp.string() + " failed (disk full?)");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, target, ec);
  if (ec)
    throw Error("VTK output: cannot rename " + tmp.string() + " to " + path + ": " + ec.message());
}

}  // namespace

void VtkWriter::write_points(const std::string& path, const std::vector<Eigen::Vector3d>& points,
                             const std::vector<VtkArray>& point_data) {
  write_atomically(path, [&](std::ostream& out) {
    const std::size_t n = points.size();
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" "
           "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <PolyData>\n";
    out << "    <Piece NumberOfPoints=\"" << n << "\" NumberOfVerts=\"" << n
        << "\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n";
    write_points_array(out, points);
    write_arrays(out, "PointData", point_data, n, path);
    out << "      <Verts>\n        <DataArray type=\"Int64\" Name=\"connectivity\" "
           "format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i) out << i << '\n';
    out << "        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" "
           "format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i) out << i + 1 << '\n';
    out << "        </DataArray>\n      </Verts>\n    </Piece>\n  </PolyData>\n</VTKFile>\n";
  });
}

void VtkWriter::write_triangles(const std::string& path, const std::vector<Eigen::Vector3d>& points,
                                const std::vector<std::array<int, 3>>& triangles,
                                const std::vector<VtkArray>& point_data,
                                const std::vector<VtkArray>& cell_data) {
  write_atomically(path, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" "
           "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <PolyData>\n";
    out << "    <Piece NumberOfPoints=\"" << points.size()
        << "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\""
        << triangles.size() << "\">\n";
    write_points_array(out, points);
    write_arrays(out, "PointData", point_data, points.size(), path);
    write_arrays(out, "CellData", cell_data, triangles.size(), path);
    out << "      <Polys>\n        <DataArray type=\"Int64\" Name=\"connectivity\" "
           "format=\"ascii\">\n";
    for (const auto& t : triangles) out << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
    out << "        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" "
           "format=\"ascii\">\n";
    for (std::size_t k = 0; k < triangles.size(); ++k) out << 3 * (k + 1) << '\n';
    out << "        </DataArray>\n      </Polys>\n    </Piece>\n  </PolyData>\n</VTKFile>\n";
  });
}

}  // namespace partita::dem
