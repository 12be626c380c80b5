#include "partita/interface/stl.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <vector>

#include <Eigen/Geometry>

#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"
#include "partita/interface/output.hpp"

namespace partita {

namespace {

struct Soup {
  std::vector<std::array<double, 9>> tris;     // three vertices per triangle
  std::vector<int> lines;                      // source line of each facet (ASCII) or 0
  std::vector<std::array<double, 3>> normals;  // each facet's stored normal (zero: none given)
};

[[noreturn]] void stl_error(const std::string& source, int line, const std::string& what) {
  throw Error(SourceLocation{source, line, 0}, "", what);
}

// Binary STL: 80-byte header, uint32 count, then per triangle: normal (3 float), 3 vertices
// (9 float), uint16 attribute = 50 bytes. Detected by size == 84 + 50 n.
bool looks_binary(const std::string& b) {
  if (b.size() < 84) return false;
  std::uint32_t n = 0;
  std::memcpy(&n, b.data() + 80, 4);
  return b.size() == 84 + 50ull * n;
}

Soup parse_binary(const std::string& b, const std::string& source) {
  std::uint32_t n = 0;
  std::memcpy(&n, b.data() + 80, 4);
  Soup s;
  s.tris.resize(n);
  s.lines.assign(n, 0);
  s.normals.assign(n, {0.0, 0.0, 0.0});
  for (std::uint32_t t = 0; t < n; ++t) {
    const char* nrm = b.data() + 84 + 50ull * t;
    for (int k = 0; k < 3; ++k) {
      float f;
      std::memcpy(&f, nrm + 4 * k, 4);
      s.normals[t][static_cast<std::size_t>(k)] = f;
    }
    const char* p = nrm + 12;
    for (int k = 0; k < 9; ++k) {
      float f;
      std::memcpy(&f, p + 4 * k, 4);
      s.tris[t][static_cast<std::size_t>(k)] = f;
    }
  }
  (void)source;
  return s;
}

Soup parse_ascii(const std::string& b, const std::string& source) {
  // solid name / facet normal nx ny nz / outer loop / vertex x y z (x3) / endloop / endfacet /
  // endsolid
  Soup s;
  std::istringstream in(b);
  std::string line;
  int lineno = 0;
  enum class St { start, solid, facet, loop, endloop, done } st = St::start;
  std::array<double, 9> tri{};
  std::array<double, 3> normal{};
  int nv = 0;
  int facet_line = 0;
  while (std::getline(in, line)) {
    ++lineno;
    std::istringstream ls(line);
    std::string word;
    if (!(ls >> word)) continue;
    auto expect = [&](const char* what) {
      stl_error(source, lineno,
                "STL syntax error: expected " + std::string(what) + ", found '" + word + "'");
    };
    switch (st) {
      case St::start:
        if (word != "solid") expect("'solid'");
        st = St::solid;
        break;
      case St::solid:
        if (word == "endsolid") {
          st = St::done;
          break;
        }
        if (word != "facet") expect("'facet' or 'endsolid'");
        facet_line = lineno;
        {  // "facet normal nx ny nz": the stored normal, where readable (else: none given)
          normal = {0.0, 0.0, 0.0};
          std::string kw;
          std::array<double, 3> nrm{};
          bool ok = static_cast<bool>(ls >> kw) && kw == "normal";
          for (int k = 0; k < 3 && ok; ++k) {
            std::string tok;
            char* end = nullptr;
            ok = static_cast<bool>(ls >> tok);
            if (ok) nrm[static_cast<std::size_t>(k)] = std::strtod(tok.c_str(), &end);
            ok = ok && end != tok.c_str() && *end == '\0';
          }
          if (ok) normal = nrm;
        }
        st = St::facet;
        break;
      case St::facet:
        if (word != "outer") expect("'outer loop'");
        st = St::loop;
        nv = 0;
        break;
      case St::loop: {
        if (word == "endloop") {
          if (nv != 3)
            stl_error(source, lineno,
                      "STL facet has " + std::to_string(nv) + " vertices; exactly 3 are required");
          st = St::endloop;
          break;
        }
        if (word != "vertex") expect("'vertex' or 'endloop'");
        if (nv >= 3)
          stl_error(source, lineno, "STL facet has more than 3 vertices; exactly 3 are required");
        for (int k = 0; k < 3; ++k) {
          std::string tok;
          if (!(ls >> tok)) stl_error(source, lineno, "STL vertex needs 3 coordinates");
          char* end = nullptr;
          const double v = std::strtod(tok.c_str(), &end);
          if (end == tok.c_str() || *end != '\0')
            stl_error(source, lineno, "STL vertex coordinate '" + tok + "' is not a number");
          tri[static_cast<std::size_t>(3 * nv + k)] = v;
        }
        ++nv;
        break;
      }
      case St::endloop:
        if (word != "endfacet") expect("'endfacet'");
        s.tris.push_back(tri);
        s.lines.push_back(facet_line);
        s.normals.push_back(normal);
        st = St::solid;
        break;
      case St::done:
        if (word == "solid") {  // several solids in one file
          st = St::solid;
          break;
        }
        expect("end of file");
    }
  }
  if (st != St::done)
    stl_error(source, lineno, "STL file ends early (truncated?): 'endsolid' is missing");
  return s;
}

// "3 (triangles 0, 5, 7)" or with the facets' lines: the first few of a list, for a message.
std::string first_few(const std::vector<std::string>& items) {
  std::string out;
  for (std::size_t k = 0; k < items.size() && k < 5; ++k) out += (k ? ", " : "") + items[k];
  if (items.size() > 5) out += ", ...";
  return out;
}

// Orientation: the facets' stored normals against their vertex order (right-hand rule), and the
// windings of neighbours (an edge shared by two triangles must run in opposite directions in
// them, else one of them is flipped). Messages, empty when the orientation is consistent.
std::vector<std::string> stl_orientation_warnings(const Soup& soup, const Mesh::Triangles& tris,
                                                  const std::string& source) {
  std::vector<std::string> warnings;
  auto name = [&](std::size_t t) {
    return soup.lines[t] ? "triangle " + std::to_string(t) + " (facet at line " +
                               std::to_string(soup.lines[t]) + ")"
                         : "triangle " + std::to_string(t);
  };
  std::vector<std::string> against;
  for (std::size_t t = 0; t < soup.tris.size() && t < soup.normals.size(); ++t) {
    const auto& v = soup.tris[t];
    const Eigen::Vector3d n(soup.normals[t][0], soup.normals[t][1], soup.normals[t][2]);
    if (!n.allFinite() || !(n.norm() > 0.0)) continue;  // no normal given: nothing to compare
    const Eigen::Vector3d a(v[0], v[1], v[2]), b(v[3], v[4], v[5]), c(v[6], v[7], v[8]);
    const Eigen::Vector3d w = (b - a).cross(c - a);
    // contradicts: pointing to the other side (a normal within 60 degrees of the surface
    // counts as neither: some writers store rough normals)
    if (n.dot(w) < -0.5 * n.norm() * w.norm()) against.push_back(name(t));
  }
  if (!against.empty())
    warnings.push_back(
        source + ": " + std::to_string(against.size()) + " of " +
        std::to_string(soup.tris.size()) +
        " facets have a stored normal that points against their vertex order (the right-hand "
        "rule gives the other side): " +
        first_few(against) + "; readers that orient by the vertex order see these facets "
        "flipped");
  // directed edges: (from, to) -> the triangle that runs it; an edge run the same way by two
  // triangles joins neighbours of opposite windings
  std::map<std::pair<int, int>, int> directed;
  std::vector<std::string> flipped;
  for (Eigen::Index t = 0; t < tris.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = tris(t, k), b = tris(t, (k + 1) % 3);
      if (a == b) continue;
      const auto [it, inserted] = directed.emplace(std::make_pair(a, b), static_cast<int>(t));
      if (!inserted && it->second != static_cast<int>(t))
        flipped.push_back(name(static_cast<std::size_t>(it->second)) + " and " +
                          name(static_cast<std::size_t>(t)));
    }
  if (!flipped.empty())
    warnings.push_back(
        source + ": " + std::to_string(flipped.size()) +
        " edges are shared by neighbours whose vertex orders disagree (each runs the edge the "
        "same way, so one of them faces the other side): " +
        first_few(flipped) + "; reorder the vertices of the flipped triangles");
  return warnings;
}

}  // namespace

Mesh parse_stl(const std::string& bytes, const std::string& source, const std::string& name,
               double scale, std::vector<std::string>* warnings) {
  if (bytes.empty()) throw Error(source + ": the STL file is empty");
  if (!(scale > 0) || !std::isfinite(scale))
    throw Error(source + ": STL scale must be a positive number, got " + std::to_string(scale));
  Soup soup;
  const bool ascii_start =
      bytes.compare(0, 5, "solid") == 0 && bytes.find("facet") != std::string::npos;
  if (looks_binary(bytes)) {
    soup = parse_binary(bytes, source);
  } else if (ascii_start || bytes.compare(0, 5, "solid") == 0) {
    soup = parse_ascii(bytes, source);
  } else if (bytes.size() >= 84) {
    std::uint32_t n = 0;
    std::memcpy(&n, bytes.data() + 80, 4);
    throw Error(source + ": not a valid STL file: as binary STL its header announces " +
                std::to_string(n) + " triangles (" + std::to_string(84 + 50ull * n) +
                " bytes) but the file has " + std::to_string(bytes.size()) +
                " bytes (truncated?), and it does not start with 'solid' as ASCII STL does");
  } else {
    throw Error(source + ": not a valid STL file (" + std::to_string(bytes.size()) +
                " bytes: too short for binary STL and not ASCII STL starting with 'solid')");
  }
  if (soup.tris.empty()) throw Error(source + ": the STL file contains no triangles");

  // Merge vertices with identical coordinates; check each triangle.
  std::map<std::array<double, 3>, int> index;
  std::vector<std::array<double, 3>> pts;
  Mesh::Triangles tris(static_cast<Eigen::Index>(soup.tris.size()), 3);
  double extent = 0;
  for (const auto& t : soup.tris)
    for (double v : t) extent = std::max(extent, std::abs(v));
  for (std::size_t t = 0; t < soup.tris.size(); ++t) {
    const auto& tri = soup.tris[t];
    const std::string where = soup.lines[t] ? "facet at line " + std::to_string(soup.lines[t])
                                            : "triangle " + std::to_string(t);
    for (double v : tri)
      if (!std::isfinite(v))
        stl_error(source, soup.lines[t], where + " has a NaN or infinite coordinate");
    Eigen::Vector3d a(tri[0], tri[1], tri[2]), b(tri[3], tri[4], tri[5]), c(tri[6], tri[7], tri[8]);
    const double area2 = (b - a).cross(c - a).norm();
    if (!(area2 > 1e-12 * extent * extent))
      stl_error(source, soup.lines[t],
                where + " has zero area (degenerate triangle); remove it or fix its vertices");
    for (int k = 0; k < 3; ++k) {
      std::array<double, 3> p{tri[3 * k] * scale, tri[3 * k + 1] * scale, tri[3 * k + 2] * scale};
      auto [it, inserted] = index.emplace(p, static_cast<int>(pts.size()));
      if (inserted) pts.push_back(p);
      tris(static_cast<Eigen::Index>(t), k) = it->second;
    }
  }
  Mesh::Points P(static_cast<Eigen::Index>(pts.size()), 3);
  for (std::size_t i = 0; i < pts.size(); ++i)
    P.row(static_cast<Eigen::Index>(i)) << pts[i][0], pts[i][1], pts[i][2];
  for (std::string& w : stl_orientation_warnings(soup, tris, source)) {
    if (warnings)
      warnings->push_back(std::move(w));
    else
      log::get("interface")->warn("{}", w);
  }
  return Mesh(name, std::move(P), std::move(tris));
}

Mesh read_stl(const std::filesystem::path& file, const std::string& name, double scale,
              std::vector<std::string>* warnings) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec))
    throw Error("cannot open STL file '" + file.string() + "': no such file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error("cannot open STL file '" + file.string() + "'");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_stl(ss.str(), file.string(), name, scale, warnings);
}

void write_stl_binary(const std::filesystem::path& file, const Mesh& mesh) {
  AtomicFile f(file, true);
  char header[80] = {};
  const std::string h = "partita binary STL: " + mesh.name();
  std::memcpy(header, h.data(), std::min<std::size_t>(h.size(), 79));
  auto& out = f.stream();
  out.write(header, 80);
  const auto n = static_cast<std::uint32_t>(mesh.num_triangles());
  out.write(reinterpret_cast<const char*>(&n), 4);
  const Mesh::Points normals = mesh.triangle_normals();
  for (Eigen::Index t = 0; t < mesh.num_triangles(); ++t) {
    float buf[12];
    for (int k = 0; k < 3; ++k) buf[k] = static_cast<float>(normals(t, k));
    for (int v = 0; v < 3; ++v)
      for (int k = 0; k < 3; ++k)
        buf[3 + 3 * v + k] = static_cast<float>(mesh.points()(mesh.triangles()(t, v), k));
    out.write(reinterpret_cast<const char*>(buf), sizeof buf);
    const std::uint16_t attr = 0;
    out.write(reinterpret_cast<const char*>(&attr), 2);
  }
  f.commit();
}

void write_stl_ascii(const std::filesystem::path& file, const Mesh& mesh) {
  AtomicFile f(file);
  auto& out = f.stream();
  out << std::setprecision(17);  // round-trips every double exactly
  const std::string solid = mesh.name().empty() ? "partita" : mesh.name();
  out << "solid " << solid << "\n";
  const Mesh::Points normals = mesh.triangle_normals();
  for (Eigen::Index t = 0; t < mesh.num_triangles(); ++t) {
    out << "  facet normal " << normals(t, 0) << " " << normals(t, 1) << " " << normals(t, 2)
        << "\n    outer loop\n";
    for (int v = 0; v < 3; ++v) {
      const auto p = mesh.points().row(mesh.triangles()(t, v));
      out << "      vertex " << p(0) << " " << p(1) << " " << p(2) << "\n";
    }
    out << "    endloop\n  endfacet\n";
  }
  out << "endsolid " << solid << "\n";
  f.commit();
}

}  // namespace partita
