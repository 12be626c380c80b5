#pragma once
// Output that people can use and that an interrupted run never leaves half-written:
// every file is written under a temporary name in the same folder and renamed when complete.

#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "partita/interface/mesh.hpp"
#include "partita/interface/vtk_xml.hpp"

namespace partita {

/// A file written under "<name>.part" and renamed to <name> by commit(). If the object dies
/// without commit() (an exception, an interrupt), the temporary is removed and an existing
/// complete file of that name is left untouched.
class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path path, bool binary = false);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ofstream& stream() { return out_; }
  /// Flush, close and rename into place. Throws partita::Error if writing failed.
  void commit();
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_, tmp_;
  std::ofstream out_;
  bool committed_ = false;
};

/// Write a whole text file atomically.
void write_file_atomically(const std::filesystem::path& path, const std::string& content);

/// A CSV time series: header "time [s],name [unit],..." and one row per record() call.
/// Rows go to "<name>.part"; every flush() (and close()) copies the complete rows into place by
/// rename, so the named file is always a complete CSV.
class CsvSeries {
 public:
  CsvSeries() = default;
  /// columns: (name, unit) pairs after the first column. Nothing is written before the first
  /// flush() (a resumed run replaces the text first: an existing file stays as it is until then).
  CsvSeries(std::filesystem::path path, std::string first_column, std::string first_unit,
            std::vector<std::pair<std::string, std::string>> columns);
  void record(double first, const std::vector<double>& values);
  void flush();
  void close();
  bool is_open() const { return !path_.empty(); }
  const std::filesystem::path& path() const { return path_; }
  /// The whole CSV text so far, header included (restart files keep it).
  const std::string& text() const { return text_; }
  /// Replace the text by one text() returned (a resumed run), and write it to the file.
  void restore_text(std::string text);

 private:
  std::filesystem::path path_;
  std::string text_;
  std::size_t flushed_size_ = 0;  // text_ already on disk
  std::size_t columns_ = 0;
};

/// A ParaView collection (.pvd) of time-stamped files, rewritten atomically at each add().
class PvdSeries {
 public:
  PvdSeries() = default;
  explicit PvdSeries(std::filesystem::path path);
  /// `file` relative to the .pvd's folder.
  void add(double time, const std::string& file);
  const std::filesystem::path& path() const { return path_; }
  const std::vector<std::pair<double, std::string>>& entries() const { return entries_; }
  /// Replace the entries (a resumed run) and rewrite the .pvd.
  void restore_entries(std::vector<std::pair<double, std::string>> entries);

 private:
  void write() const;
  std::filesystem::path path_;
  std::vector<std::pair<double, std::string>> entries_;
};

/// Removes the ParaView collections (*.pvd) in `dir` and the files they list, so that a new run
/// into an existing output folder leaves no frames of an earlier, longer run behind. Only plain
/// file names inside `dir` are removed (never a path with a folder part); other files stay.
/// Returns the number of files removed. A missing folder is not an error.
int remove_pvd_series(const std::filesystem::path& dir);

/// Named point or cell arrays for VTK output (N x C each).
using VtkArrays = std::vector<std::pair<std::string, Eigen::MatrixXd>>;

/// Write a mesh (points + triangles, or points only as vertices) as VTK XML PolyData (.vtp) in
/// the given format (vtk_xml.hpp), atomically. `points` overrides the mesh's coordinates (e.g.
/// deformed) when non-empty. Non-finite values are written as 0 (data not exchanged yet).
void write_vtp(const std::filesystem::path& path, const Mesh& mesh, const VtkArrays& point_data,
               const VtkArrays& cell_data = {}, const Mesh::Points* points = nullptr,
               const vtk::Options& options = {});

}  // namespace partita
