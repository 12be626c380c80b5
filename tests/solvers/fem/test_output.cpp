// VTK XML output and scalar monitors.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "partita/fem/fem.hpp"

using namespace partita::fem;

TEST_CASE("fem vtu output for every element type", "[fem][output]") {
  const auto dir = std::filesystem::temp_directory_path() / "partita_fem_tests";
  std::filesystem::create_directories(dir);
  const std::vector<std::pair<ElementType, int>> types = {{ElementType::Hex8, 12},
                                                          {ElementType::Hex20, 25},
                                                          {ElementType::Tet4, 10},
                                                          {ElementType::Tet10, 24}};
  for (const auto& [type, vtk] : types) {
    Model model(make_box_mesh({Vec3::Zero(), Vec3(1, 0.2, 0.2), {4, 1, 1}, type}));
    model.fix("xmin");
    model.add_pressure("zmax", 1e5);
    StructuralSolver s(model);
    s.solve_static();
    const auto path = (dir / ("out_" + std::string(to_string(type)) + ".vtu")).string();
    write_vtu(path, s);
    CHECK_FALSE(std::filesystem::exists(path + ".tmp"));
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    const std::string xml = text.str();
    CHECK(xml.find("<VTKFile type=\"UnstructuredGrid\"") != std::string::npos);
    CHECK(xml.find("NumberOfPoints=\"" + std::to_string(s.mesh().num_nodes()) + "\"") !=
          std::string::npos);
    for (const char* name : {"displacement", "velocity", "stress", "von_mises"}) {
      CHECK(xml.find(std::string("Name=\"") + name + "\"") != std::string::npos);
    }
    CHECK(xml.find("\n          " + std::to_string(vtk) + "\n") != std::string::npos);
    CHECK(xml.rfind("</VTKFile>") != std::string::npos);
    // monitors
    CHECK(s.max_displacement() > 0.0);
    CHECK(s.strain_energy() > 0.0);
    CHECK(s.kinetic_energy() == 0.0);
    CHECK(s.reaction("xmin")[2] == Approx(1e5 * 0.2).epsilon(1e-9));
    const Eigen::VectorXd vm = StructuralSolver::von_mises(s.nodal_stress());
    CHECK(vm.minCoeff() >= 0.0);
    CHECK(vm.maxCoeff() > 0.0);
  }
  CHECK_THROWS_AS(write_vtu("/nonexistent/dir/out.vtu", StructuralSolver(Model(make_box_mesh({})))),
                  Error);
}

TEST_CASE("fem hex8 incompatible modes: no volumetric locking at nu = 0.45", "[fem][static]") {
  // Cantilever of nearly incompressible material: QM6 stays close to Hex20, plain Hex8 locks.
  auto tip = [](ElementType type, Hex8Formulation f) {
    Model m(make_box_mesh({Vec3::Zero(), Vec3(1, 0.1, 0.1), {20, 2, 2}, type}),
            Material{2.5e6, 0.45, 1000});
    m.set_hex8_formulation(f);
    m.fix("xmin");
    m.add_traction("xmax", Vec3(0, 0, -100.0));
    StructuralSolver s(m);
    s.solve_static();
    double sum = 0.0;
    for (auto n : s.mesh().node_set("xmax")) sum -= s.displacement(n)[2];
    return sum / static_cast<double>(s.mesh().node_set("xmax").size());
  };
  const double reference = tip(ElementType::Hex20, Hex8Formulation::IncompatibleModes);
  const double qm6 = tip(ElementType::Hex8, Hex8Formulation::IncompatibleModes);
  const double full = tip(ElementType::Hex8, Hex8Formulation::Full);
  INFO("nu = 0.45 tip: hex20 " << reference << ", hex8 QM6 " << qm6 << ", hex8 full " << full);
  CHECK(std::abs(qm6 / reference - 1) < 0.03);
  CHECK(full / reference < 0.85);
}
