// Gmsh 4.1 import: committed meshes of the unit cube (data/*.geo made them with gmsh 4.8),
// physical groups as regions / faces / node sets; malformed files give file:line errors.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>

#include "fem_test_helpers.hpp"
#include "partita/fem/gmsh_reader.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;

namespace {
std::string data(const std::string& name) {
  return std::string(PARTITA_SOURCE_DIR) + "/tests/solvers/fem/data/" + name;
}
std::string write_temp(const std::string& name, const std::string& text) {
  const auto dir = std::filesystem::temp_directory_path() / "partita_fem_tests";
  std::filesystem::create_directories(dir);
  const auto path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}
const char* kHeader = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
// one Tet4 with nodes 1..4
const char* kNodes =
    "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n";
}  // namespace

TEST_CASE("fem gmsh import of committed meshes", "[fem][gmsh]") {
  for (const auto& [file, type] : {std::pair{"cube_hex20.msh", ElementType::Hex20},
                                   std::pair{"cube_tet10.msh", ElementType::Tet10}}) {
    INFO(file);
    Mesh mesh = read_gmsh(data(file));
    REQUIRE(mesh.num_elements() > 0);
    for (const auto& e : mesh.elements()) CHECK(e.type == type);
    CHECK(mesh.region_names() == std::vector<std::string>{"solid"});
    CHECK(mesh.has_face("top"));
    CHECK(mesh.has_face("bottom"));
    CHECK(mesh.has_node_set("top"));
    CHECK(mesh.has_node_set("solid"));
    CHECK(mesh.face_nodes("top") == mesh.node_set("top"));
    ElementIntegrator integ;
    double volume = 0.0;
    for (const auto& e : mesh.elements()) {
      ElementCoordinates x(node_count(e.type), 3);
      for (int a = 0; a < node_count(e.type); ++a) x.row(a) = mesh.node(e.nodes[a]).transpose();
      volume += integ.volume(e.type, x);
    }
    CHECK(volume == Approx(1.0).epsilon(1e-12));
    // patch test on the imported mesh: u = G x prescribed on the cube's boundary
    mesh.add_node_set_where(
        "boundary", [](const Vec3& x) { return x.minCoeff() < 1e-12 || x.maxCoeff() > 1 - 1e-12; });
    Model model(mesh);
    Mat3 g;
    g << 1e-3, 2e-4, 0, -1e-4, 5e-4, 3e-4, 0, 1e-4, -2e-4;
    for (int c = 0; c < 3; ++c) {
      model.prescribe_field("boundary", c,
                            [g, c](const Vec3& x, double) { return g.row(c).dot(x); });
    }
    model.add_pressure("top", 0.0);
    StructuralSolver s(model);
    s.solve_static();
    double err = 0.0;
    for (std::size_t i = 0; i < mesh.num_nodes(); ++i)
      err = std::max(err, (s.displacement(i) - g * mesh.node(i)).norm());
    CHECK(err < 1e-10 * 1e-3);
    // faces are oriented outward
    Vec3 top = Vec3::Zero(), bottom = Vec3::Zero();
    for (const auto& q : s.face_quadrature_points("top")) top += q.weight * q.normal;
    for (const auto& q : s.face_quadrature_points("bottom")) bottom += q.weight * q.normal;
    CHECK((top - Vec3(0, 0, 1)).norm() < 1e-12);
    CHECK((bottom - Vec3(0, 0, -1)).norm() < 1e-12);
  }
}

TEST_CASE("fem gmsh import: malformed files are clear errors", "[fem][gmsh]") {
  CHECK_THROWS_WITH(read_gmsh("/nonexistent/mesh.msh"),
                    Catch::Contains("/nonexistent/mesh.msh") && Catch::Contains("cannot open"));

  const auto v22 = write_temp("v22.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n");
  CHECK_THROWS_WITH(read_gmsh(v22), Catch::Contains("v22.msh:2:") && Catch::Contains("4.1"));

  const auto binary = write_temp("binary.msh", "$MeshFormat\n4.1 1 8\n$EndMeshFormat\n");
  CHECK_THROWS_WITH(read_gmsh(binary),
                    Catch::Contains("binary.msh:2:") && Catch::Contains("ASCII"));

  const auto short_element =
      write_temp("short.msh", std::string(kHeader) + kNodes +
                                  "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3\n$EndElements\n");
  CHECK_THROWS_WITH(read_gmsh(short_element),
                    Catch::Contains("short.msh:19:") && Catch::Contains("needs 4 nodes"));

  const auto prism =
      write_temp("prism.msh", std::string(kHeader) + kNodes +
                                  "$Elements\n1 1 1 1\n3 1 6 1\n1 1 2 3 4 1 2\n$EndElements\n");
  CHECK_THROWS_WITH(read_gmsh(prism), Catch::Contains("prism.msh:18:") &&
                                          Catch::Contains("not supported") &&
                                          Catch::Contains("17 (hex20)"));

  const auto missing_node =
      write_temp("missing.msh", std::string(kHeader) + kNodes +
                                    "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 9\n$EndElements\n");
  CHECK_THROWS_WITH(read_gmsh(missing_node),
                    Catch::Contains("missing.msh:19:") && Catch::Contains("node 9"));

  const auto garbage = write_temp(
      "garbage.msh", std::string(kHeader) +
                         "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 zero 0\n0 1 0\n0 0 1\n");
  CHECK_THROWS_WITH(read_gmsh(garbage),
                    Catch::Contains("garbage.msh:12:") && Catch::Contains("node coordinates"));

  const auto truncated =
      write_temp("truncated.msh", std::string(kHeader) + "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n");
  // (4 nodes announced, fewer bytes left than 4 nodes take: found at the header)
  CHECK_THROWS_WITH(read_gmsh(truncated),
                    Catch::Contains("truncated.msh:5:") && Catch::Contains("file ends too soon"));

  const auto no_volume =
      write_temp("novolume.msh", std::string(kHeader) + kNodes +
                                     "$Elements\n1 1 1 1\n2 1 2 1\n1 1 2 3\n$EndElements\n");
  CHECK_THROWS_WITH(read_gmsh(no_volume), Catch::Contains("no volume elements"));

  // a good one-element file reads
  const auto good =
      write_temp("good.msh", std::string(kHeader) + kNodes +
                                 "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n");
  CHECK(read_gmsh(good).num_elements() == 1);
}
