#include "partita/interface/output.hpp"

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
void write_vtp(const std::filesystem::path& path, const Mesh& mesh, const VtkArrays& point_data,
               const VtkArrays& cell_data, const Mesh::Points* points,
               const vtk::Options& options) {
  const Mesh::Points& P = (points && points->rows() > 0) ? *points : mesh.points();
  const auto np = static_cast<std::size_t>(P.rows());
  const bool tris = mesh.has_triangles();
  vtk::PolyData piece;
  piece.points = vtk::DataArray::rows("Points", P, true);
  if (tris) {
    const auto nt = static_cast<std::size_t>(mesh.num_triangles());
    std::vector<std::int32_t> conn(3 * nt);
    for (std::size_t c = 0, k = 0; c < nt; ++c)
      for (int j = 0; j < 3; ++j) conn[k++] = mesh.triangles()(static_cast<Eigen::Index>(c), j);
    piece.polys = {vtk::DataArray::own("connectivity", std::move(conn)),
                   vtk::DataArray::sequence("offsets", nt, 3, 3)};
  } else {
    piece.verts = vtk::Cells::vertices(np);
  }
  for (const auto& [n, a] : point_data)
    piece.point_data.push_back(vtk::DataArray::rows(n, a, true));
  for (const auto& [n, a] : cell_data) piece.cell_data.push_back(vtk::DataArray::rows(n, a, true));
  vtk::write(path, piece, options);
}

}  // namespace partita
