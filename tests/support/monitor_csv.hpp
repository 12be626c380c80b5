#pragma once
// Reading a monitor CSV file of a run (header "time [s],name [unit],..."; one row per window)
// and averaging its columns over the last rows. Header-only, shared by the tests that drive the
// partita executable.

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace partita::test {

struct MonitorCsv {
  std::vector<std::string> header;        ///< column names without their " [unit]"
  std::vector<std::vector<double>> rows;  ///< one per line after the header

  static MonitorCsv read(const std::filesystem::path& file) {
    MonitorCsv csv;
    std::ifstream in(file);
    std::string line;
    std::getline(in, line);
    std::stringstream h(line);
    for (std::string c; std::getline(h, c, ',');) csv.header.push_back(c.substr(0, c.find(" [")));
    while (std::getline(in, line)) {
      std::stringstream s(line);
      std::vector<double> row;
      for (std::string c; std::getline(s, c, ',');) row.push_back(std::stod(c));
      csv.rows.push_back(row);
    }
    return csv;
  }

  /// Mean of every column over the last `fraction` of the rows (e.g. a bed at rest).
  std::map<std::string, double> mean_over_last(double fraction) const {
    std::map<std::string, double> mean;
    if (rows.empty()) return mean;
    std::size_t count =
        static_cast<std::size_t>(fraction * static_cast<double>(rows.size()) + 1e-9);
    if (count == 0) count = 1;
    const std::size_t from = rows.size() - count;
    for (std::size_t c = 0; c < header.size(); ++c) {
      double s = 0;
      for (std::size_t i = from; i < rows.size(); ++i) s += rows[i][c];
      mean[header[c]] = s / static_cast<double>(count);
    }
    return mean;
  }
};

}  // namespace partita::test
