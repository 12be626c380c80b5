#include "partita/interface/output.hpp"

#include <charconv>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "partita/interface/error.hpp"

namespace partita {

// ---------------------------------------------------------------------------------------------
AtomicFile::AtomicFile(std::filesystem::path path, bool binary) : path_(std::move(path)) {
  tmp_ = path_;
  tmp_ += ".part";
  if (path_.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(path_.parent_path(), ec);
  }
  out_.open(tmp_, binary ? std::ios::binary | std::ios::trunc : std::ios::trunc);
  if (!out_)
    throw Error("cannot write '" + tmp_.string() + "' (does the folder exist and is it writable?)");
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    out_.close();
    std::error_code ec;
    std::filesystem::remove(tmp_, ec);
  }
}

void AtomicFile::commit() {
  out_.flush();
  const bool ok = static_cast<bool>(out_);
  out_.close();
  if (!ok) throw Error("writing '" + path_.string() + "' failed (disk full?)");
  std::error_code ec;
  std::filesystem::rename(tmp_, path_, ec);
  if (ec)
    throw Error("cannot rename '" + tmp_.string() + "' to '" + path_.string() +
                "': " + ec.message());
  committed_ = true;
}

void write_file_atomically(const std::filesystem::path& path, const std::string& content) {
  AtomicFile f(path);
  f.stream() << content;
  f.commit();
}

// ---------------------------------------------------------------------------------------------
namespace {
std::string header_cell(const std::string& name, const std::string& unit) {
  return unit.empty() ? name : name + " [" + unit + "]";
}
std::string fmt_double(double v) {
  std::ostringstream s;
  s << std::setprecision(10) << v;
  return s.str();
}
}  // namespace

CsvSeries::CsvSeries(std::filesystem::path path, std::string first_column, std::string first_unit,
                     std::vector<std::pair<std::string, std::string>> columns)
    : path_(std::move(path)), columns_(columns.size()) {
  text_ = header_cell(first_column, first_unit);
  for (const auto& [n, u] : columns) text_ += "," + header_cell(n, u);
  text_ += "\n";
  flush();
}

void CsvSeries::record(double first, const std::vector<double>& values) {
  if (values.size() != columns_)
    throw Error("CSV '" + path_.string() + "': a row has " + std::to_string(values.size()) +
                " values, the header " + std::to_string(columns_));
  text_ += fmt_double(first);
  for (double v : values) text_ += "," + fmt_double(v);
  text_ += "\n";
}

void CsvSeries::flush() {
  if (path_.empty() || flushed_size_ == text_.size()) return;  // nothing new
  write_file_atomically(path_, text_);
  flushed_size_ = text_.size();
}

void CsvSeries::restore_text(std::string text) {
  text_ = std::move(text);
  flushed_size_ = 0;
  flush();
}

void CsvSeries::close() {
  flush();
  path_.clear();
}

// ---------------------------------------------------------------------------------------------
PvdSeries::PvdSeries(std::filesystem::path path) : path_(std::move(path)) {}

void PvdSeries::add(double time, const std::string& file) {
  entries_.emplace_back(time, file);
  write();
}

void PvdSeries::restore_entries(std::vector<std::pair<double, std::string>> entries) {
  entries_ = std::move(entries);
  write();
}

void PvdSeries::write() const {
  std::ostringstream s;
  s << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" "
       "byte_order=\"LittleEndian\">\n"
       "  <Collection>\n";
  for (const auto& [t, f] : entries_)
    s << "    <DataSet timestep=\"" << std::setprecision(12) << t
      << "\" group=\"\" part=\"0\" file=\"" << f << "\"/>\n";
  s << "  </Collection>\n</VTKFile>\n";
  write_file_atomically(path_, s.str());
}

int remove_pvd_series(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return 0;
  std::vector<fs::path> collections;
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (entry.is_regular_file(ec) && entry.path().extension() == ".pvd")
      collections.push_back(entry.path());
  int removed = 0;
  for (const fs::path& pvd : collections) {
    std::ifstream in(pvd);
    std::string line;
    while (std::getline(in, line)) {
      const std::string key = "file=\"";
      const auto a = line.find(key);
      if (a == std::string::npos) continue;
      const auto b = line.find('"', a + key.size());
      if (b == std::string::npos) continue;
      const fs::path name = line.substr(a + key.size(), b - a - key.size());
      // a plain name only: nothing outside the folder, no "..", no absolute path
      if (name.empty() || name.has_parent_path() || name == "." || name == "..") continue;
      if (fs::remove(dir / name, ec)) ++removed;
    }
    in.close();
    if (fs::remove(pvd, ec)) ++removed;
  }
  return removed;
}

// ---------------------------------------------------------------------------------------------
namespace {
// A double as text with `digits` significant digits (std::to_chars: several times faster than
// an ostream's formatting, which dominated the output time).
void put_number(std::ostream& out, double v, int digits) {
  char buf[40];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, digits);
  out.write(buf, r.ptr - buf);
}

void write_array(std::ostream& out, const std::string& name, const Eigen::MatrixXd& a) {
  out << "        <DataArray type=\"Float64\" Name=\"" << name << "\" NumberOfComponents=\""
      << a.cols() << "\" format=\"ascii\">\n          ";
  for (Eigen::Index i = 0; i < a.rows(); ++i)
    for (Eigen::Index k = 0; k < a.cols(); ++k) {
      put_number(out, std::isfinite(a(i, k)) ? a(i, k) : 0.0, 10);
      out << ' ';
    }
  out << "\n        </DataArray>\n";
}
}  // namespace

void write_vtp(const std::filesystem::path& path, const Mesh& mesh, const VtkArrays& point_data,
               const VtkArrays& cell_data, const Mesh::Points* points) {
  const Mesh::Points& P = (points && points->rows() > 0) ? *points : mesh.points();
  const Eigen::Index np = P.rows();
  const bool tris = mesh.has_triangles();
  const Eigen::Index nc = tris ? mesh.num_triangles() : np;
  for (const auto& [n, a] : point_data)
    if (a.rows() != np)
      throw Error("VTK output '" + path.string() + "': point array '" + n + "' has wrong length");
  for (const auto& [n, a] : cell_data)
    if (a.rows() != nc)
      throw Error("VTK output '" + path.string() + "': cell array '" + n + "' has wrong length");
  AtomicFile f(path);
  auto& out = f.stream();
  out << std::setprecision(10);
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" "
         "byte_order=\"LittleEndian\">\n"
      << "  <PolyData>\n    <Piece NumberOfPoints=\"" << np << "\" NumberOfVerts=\""
      << (tris ? 0 : np) << "\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\""
      << (tris ? nc : 0) << "\">\n";
  out << "      <Points>\n";
  write_array(out, "Points", P);
  out << "      </Points>\n";
  out << "      <PointData>\n";
  for (const auto& [n, a] : point_data) write_array(out, n, a);
  out << "      </PointData>\n      <CellData>\n";
  for (const auto& [n, a] : cell_data) write_array(out, n, a);
  out << "      </CellData>\n";
  const char* kind = tris ? "Polys" : "Verts";
  const int per = tris ? 3 : 1;
  out << "      <" << kind
      << ">\n        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n          ";
  for (Eigen::Index c = 0; c < nc; ++c)
    for (int k = 0; k < per; ++k) out << (tris ? mesh.triangles()(c, k) : c) << ' ';
  out << "\n        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" "
         "format=\"ascii\">\n          ";
  for (Eigen::Index c = 0; c < nc; ++c) out << (c + 1) * per << ' ';
  out << "\n        </DataArray>\n      </" << kind
      << ">\n    </Piece>\n  </PolyData>\n</VTKFile>\n";
  f.commit();
}

}  // namespace partita
