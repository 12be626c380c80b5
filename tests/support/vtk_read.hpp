#pragma once
// A VTK XML file as VTK's own reader sees it (tests/support/vtk_arrays.py, python3-vtk9): the
// points, cells and every point and cell array, values exact (printed in round-trip form).
// Header-only, for the tests of the VTK writer and of the adapters' output.

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "run_command.hpp"

namespace partita::test {

struct VtkContent {
  struct Array {
    std::string type;  ///< VTK's name: double, float, long long, int, unsigned char, ...
    std::size_t tuples = 0;
    int components = 0;
    std::vector<double> values;      ///< floating-point arrays
    std::vector<std::int64_t> ints;  ///< integer arrays
  };
  struct CellBlock {
    std::size_t count = 0;
    std::vector<std::int64_t> connectivity, offsets;
  };
  std::string text;  ///< everything vtk_arrays.py printed (equal text: equal content)
  bool ok = false;   ///< VTK read the file
  std::size_t points = 0;
  std::vector<double> xyz;
  std::map<std::string, CellBlock> cells;  ///< "verts", "polys" (.vtp) or "cells" (.vtu)
  std::vector<std::int64_t> types;         ///< .vtu cell types
  std::map<std::string, Array> point, cell;
  std::map<std::string, std::string> active;  ///< "point Scalars" -> array name
};

inline VtkContent read_vtk(const std::filesystem::path& file) {
  VtkContent c;
  const auto r =
      run_command("/usr/bin/python3 " +
                  quote(std::string(PARTITA_SOURCE_DIR) + "/tests/support/vtk_arrays.py") + " " +
                  quote(file.string()));
  c.text = r.output;
  c.ok = r.status == 0;
  if (!c.ok) return c;
  std::istringstream in(r.output);
  std::string line;
  auto ints = [](std::istringstream& s, std::size_t n) {
    std::vector<std::int64_t> v(n);
    for (auto& x : v) s >> x;
    return v;
  };
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string kind;
    s >> kind;
    if (kind == "points") {
      int three = 0;
      s >> c.points >> three;
      std::string tok;
      while (s >> tok) c.xyz.push_back(std::strtod(tok.c_str(), nullptr));
    } else if (kind == "cells") {
      std::string which, word;
      VtkContent::CellBlock b;
      s >> which >> b.count >> word;
      std::string tok;
      while (s >> tok && tok != "offsets") b.connectivity.push_back(std::stoll(tok));
      while (s >> tok) b.offsets.push_back(std::stoll(tok));
      c.cells[which] = b;
    } else if (kind == "types") {
      std::size_t n = 0;
      s >> n;
      c.types = ints(s, n);
    } else if (kind == "point" || kind == "cell") {
      VtkContent::Array a;
      std::string name, type;
      s >> name >> type;
      if (type == "long" || type == "unsigned") {  // "long long", "unsigned char"
        std::string more;
        s >> more;
        type += " " + more;
      }
      a.type = type;
      s >> a.tuples >> a.components;
      const bool real = type == "double" || type == "float";
      std::string tok;
      while (s >> tok) {
        if (real)
          a.values.push_back(std::strtod(tok.c_str(), nullptr));
        else
          a.ints.push_back(std::stoll(tok));
      }
      (kind == "point" ? c.point : c.cell)[name] = a;
    } else if (kind == "active") {
      std::string where, attr, name;
      s >> where >> attr >> name;
      c.active[where + " " + attr] = name;
    }
  }
  return c;
}

}  // namespace partita::test
