#pragma once
// Files for the tests that drive the partita executable: a fresh scratch folder per test and
// process, and a file's bytes. Header-only, beside run_command.hpp.

#include <unistd.h>

#include <filesystem>
#include <fstream>
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

}  // namespace partita::test
