#pragma once
// Files for the tests that drive the partita executable: a fresh scratch folder per test and
// process, a file's bytes, and the result files of a run. Header-only, beside run_command.hpp.

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

namespace partita::test {

/// An empty folder <tmp>/partita_<group>_<name>_<pid> (removed first if it exists).
inline std::filesystem::path scratch_dir(const std::string& group, const std::string& name) {
  const std::filesystem::path d = std::filesystem::temp_directory_path() /
                                  ("partita_" + group + "_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

/// The whole file as bytes ("" if it cannot be read).
inline std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Every file of a run's folder that a user reads: the CSV files and everything under vtk/.
inline std::set<std::string> result_files(const std::filesystem::path& dir) {
  std::set<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".csv") files.insert(e.path().filename().string());
  for (const auto& e : std::filesystem::directory_iterator(dir / "vtk"))
    files.insert("vtk/" + e.path().filename().string());
  return files;
}

}  // namespace partita::test
