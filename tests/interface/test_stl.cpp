#include <catch2/catch.hpp>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "partita/interface/error.hpp"
#include "partita/interface/stl.hpp"

namespace fs = std::filesystem;
using partita::Mesh;

namespace {
fs::path tmpdir() {
  fs::path d = fs::temp_directory_path() / ("partita_stl_test_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}
// A plate 20 x 20 mm split into 2 n^2 triangles with float-exact random interior coordinates.
Mesh plate(int n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> jitter(-0.2f, 0.2f);
  Mesh::Points p((n + 1) * (n + 1), 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const bool inner = i > 0 && i < n && j > 0 && j < n;
      const float x = static_cast<float>(0.02 * (i + (inner ? jitter(rng) : 0.f)) / n);
      const float y = static_cast<float>(0.02 * (j + (inner ? jitter(rng) : 0.f)) / n);
      p.row(j * (n + 1) + i) << x, y, 0.0f;
    }
  Mesh::Triangles t(2 * n * n, 3);
  int k = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      t.row(k++) << a, b, d;
      t.row(k++) << a, d, c;
    }
  return Mesh("plate", p, t);
}
std::string slurp(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}
}  // namespace

TEST_CASE("STL round trip, binary and ASCII, preserves coordinates exactly", "[interface][stl]") {
  const Mesh m = plate(8);
  const fs::path d = tmpdir();
  for (bool binary : {true, false}) {
    // The extension does not decide the format: both files are called .stl.
    const fs::path f = d / (binary ? "b.stl" : "a.stl");
    if (binary)
      partita::write_stl_binary(f, m);
    else
      partita::write_stl_ascii(f, m);
    const Mesh r = partita::read_stl(f, "plate");
    REQUIRE(r.size() == m.size());  // shared vertices merged back
    REQUIRE(r.num_triangles() == m.num_triangles());
    for (Eigen::Index t = 0; t < m.num_triangles(); ++t)
      for (int v = 0; v < 3; ++v)
        CHECK(r.points().row(r.triangles()(t, v)) == m.points().row(m.triangles()(t, v)));
    CHECK(r.total_area() == Approx(4e-4).epsilon(1e-6));
    CHECK_FALSE(fs::exists(fs::path(f.string() + ".part")));
  }
  fs::remove_all(d);
}

TEST_CASE("STL errors are clear", "[interface][stl]") {
  const fs::path d = tmpdir();
  const Mesh m = plate(2);
  partita::write_stl_binary(d / "ok.stl", m);
  const std::string bin = slurp(d / "ok.stl");
  auto msg = [&](const std::string& bytes) {
    try {
      partita::parse_stl(bytes, "x.stl");
    } catch (const partita::Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  CHECK_THAT(msg(""), Catch::Contains("x.stl") && Catch::Contains("empty"));
  CHECK_THAT(msg(bin.substr(0, bin.size() - 7)), Catch::Contains("truncated"));
  CHECK_THAT(msg("solid a\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n"),
             Catch::Contains("x.stl:4") && Catch::Contains("endsolid"));
  CHECK_THAT(msg("solid a\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 nan\n   vertex 1 0 0\n "
                 "  vertex 0 1 0\n"
                 "  endloop\n endfacet\nendsolid a\n"),
             Catch::Contains("x.stl:2") && Catch::Contains("NaN or infinite"));
  CHECK_THAT(msg("solid a\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   "
                 "vertex 2 0 0\n"
                 "  endloop\n endfacet\nendsolid a\n"),
             Catch::Contains("zero area"));
  CHECK_THAT(msg("solid a\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 zero\n"),
             Catch::Contains("x.stl:4") && Catch::Contains("not a number"));
  CHECK_THAT(msg("solid a\nendsolid a\n"), Catch::Contains("no triangles"));
  // Binary with an infinite coordinate.
  std::string inf = bin;
  const float big = std::numeric_limits<float>::infinity();
  std::memcpy(&inf[84 + 12], &big, 4);
  CHECK_THAT(msg(inf), Catch::Contains("triangle 0") && Catch::Contains("infinite"));
  CHECK_THROWS_WITH(partita::read_stl(d / "missing.stl"), Catch::Contains("no such file"));
  fs::remove_all(d);
}

TEST_CASE("stl: orientation that contradicts itself is reported, counted, first triangles named",
          "[interface][stl]") {
  // Two triangles of the unit square z = 0 sharing the edge (1,0)-(0,1); both wound
  // counter-clockwise seen from +z (right-hand-rule normal +z) unless `flip` reverses the second.
  auto square = [](const char* n0, const char* n1, bool flip) {
    std::string s = "solid sq\n";
    s += std::string("facet normal ") + n0 +
         "\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n";
    s += std::string("facet normal ") + n1 + "\nouter loop\n" +
         (flip ? "vertex 1 0 0\nvertex 0 1 0\nvertex 1 1 0\n"
               : "vertex 1 0 0\nvertex 1 1 0\nvertex 0 1 0\n") +
         "endloop\nendfacet\nendsolid sq\n";
    return s;
  };
  std::vector<std::string> w;
  // consistent: nothing to say; a normal left at zero (not given) neither
  (void)partita::parse_stl(square("0 0 1", "0 0 1", false), "ok.stl", "sq", 1.0, &w);
  (void)partita::parse_stl(square("0 0 0", "0 0 1", false), "ok.stl", "sq", 1.0, &w);
  CHECK(w.empty());
  // the second facet's stored normal points against its vertex order
  (void)partita::parse_stl(square("0 0 1", "0 0 -1", false), "normal.stl", "sq", 1.0, &w);
  REQUIRE(w.size() == 1);
  INFO(w[0]);
  CHECK(w[0].find("normal.stl: 1 of 2 facets have a stored normal that points against") !=
        std::string::npos);
  CHECK(w[0].find("triangle 1 (facet at line 9)") != std::string::npos);
  // the second triangle wound the other way (its normal agrees with its own order): the shared
  // edge runs the same way in both
  w.clear();
  (void)partita::parse_stl(square("0 0 1", "0 0 -1", true), "winding.stl", "sq", 1.0, &w);
  REQUIRE(w.size() == 1);
  INFO(w[0]);
  CHECK(w[0].find("winding.stl: 1 edges are shared by neighbours whose vertex orders disagree") !=
        std::string::npos);
  CHECK(w[0].find("triangle 0 (facet at line 2) and triangle 1 (facet at line 9)") !=
        std::string::npos);
  // a written mesh (normals from the vertex order, windings of a consistent plate) reads back
  // without a word, in binary (float normals) as in ASCII
  const fs::path d = tmpdir();
  partita::write_stl_binary(d / "plate_b.stl", plate(6));
  partita::write_stl_ascii(d / "plate_a.stl", plate(6));
  w.clear();
  (void)partita::read_stl(d / "plate_b.stl", "p", 1.0, &w);
  (void)partita::read_stl(d / "plate_a.stl", "p", 1.0, &w);
  CHECK(w.empty());
}
