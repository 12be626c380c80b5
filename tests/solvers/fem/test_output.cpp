// Scalar monitors (the VTK files are the FEM adapter's: tests/adapters/test_output.cpp).
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "partita/fem/fem.hpp"

using namespace partita::fem;

TEST_CASE("fem monitors for every element type", "[fem][output]") {
  // (the .vtu file of each element type is tested through the FEM adapter, which writes it:
  // tests/adapters/test_output.cpp)
  for (const ElementType type :
       {ElementType::Hex8, ElementType::Hex20, ElementType::Tet4, ElementType::Tet10}) {
    Model model(make_box_mesh({Vec3::Zero(), Vec3(1, 0.2, 0.2), {4, 1, 1}, type}));
    model.fix("xmin");
    model.add_pressure("zmax", 1e5);
    StructuralSolver s(model);
    s.solve_static();
    CHECK(s.max_displacement() > 0.0);
    CHECK(s.strain_energy() > 0.0);
    CHECK(s.kinetic_energy() == 0.0);
    CHECK(s.reaction("xmin")[2] == Approx(1e5 * 0.2).epsilon(1e-9));
    const Eigen::VectorXd vm = StructuralSolver::von_mises(s.nodal_stress());
    CHECK(vm.minCoeff() >= 0.0);
    CHECK(vm.maxCoeff() > 0.0);
  }
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
