// Energies by part: plastic work, strain energy and kinetic energy per element region,
// summing to the model's totals, against a closed-form two-material case.
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <numeric>

#include "partita/fem/box_mesher.hpp"
#include "partita/fem/j2_plasticity_law.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;

TEST_CASE("region energies: two materials in uniaxial strain, plastic work sigma_y p V per part",
          "[fem][energies]") {
  // A block L x w x t in uniaxial strain (u_y = u_z = 0 at every node, u_x = eps L at x = L),
  // its half y < w/2 of a soft steel (sigma_y = 250 MPa), the other half hard (400 MPa), both
  // perfectly plastic. u_x = eps x is exact (no shear anywhere; the constraints take the
  // lateral stresses, which differ between the parts), so each part is homogeneous:
  //   eps_p = p diag(1, -1/2, -1/2) (eqps = p), dev e = diag(2/3, -1/3, -1/3)(eps - 3p/2),
  //   yield 2 mu (eps - 3p/2) = sigma_y  =>  p = 2/3 (eps - sigma_y / (2 mu)),
  //   W_p = sigma_y p V,  W = K eps^2 / 2 + mu (2/3)(eps - 3p/2)^2 per volume.
  constexpr double kE = 210e9, kNu = 0.3, kRho = 7850.0;
  const double mu = kE / (2.0 * (1.0 + kNu)), bulk = kE / (3.0 * (1.0 - 2.0 * kNu));
  const double length = 0.4, width = 0.1, thickness = 0.02, eps = 0.01;
  Mesh mesh = make_box_mesh(
      {Vec3::Zero(), Vec3(length, width, thickness), {4, 2, 1}, ElementType::Hex8});
  mesh.assign_region_where("soft", [&](const Vec3& c) { return c.y() < 0.5 * width; });
  mesh.assign_region_where("hard", [&](const Vec3& c) { return c.y() > 0.5 * width; });
  Model m(std::move(mesh));
  const std::vector<double> yield = {250e6, 400e6};
  m.set_material_law("soft", std::make_shared<J2PlasticityLaw>(kE, kNu, kRho,
                                                               HardeningCurve::linear(yield[0], 0)));
  m.set_material_law("hard", std::make_shared<J2PlasticityLaw>(kE, kNu, kRho,
                                                               HardeningCurve::linear(yield[1], 0)));
  m.fix("all", {1, 2});
  m.fix("xmin", {0});
  m.prescribe("xmax", 0, [&](double t) { return eps * length * t; });
  // steps that end where each part starts to yield (eps = sigma_y / (2 mu)): the law's plastic
  // work, trapezoidal in sigma : d eps_p, is then exact (a step that crosses the yield point
  // takes 1/2 (sigma_n + sigma_y) for sigma_y over its plastic part: 2.7 % low here in one step)
  SolverOptions opt;
  opt.newton.load_steps = 5;
  StructuralSolver s(std::move(m), opt);
  const double t_soft = yield[0] / (2.0 * mu) / eps, t_hard = yield[1] / (2.0 * mu) / eps;
  s.step_static(t_soft);
  s.step_static(t_hard - t_soft);
  s.step_static(1.0 - t_hard);
  const RegionEnergies e = s.region_energies();
  const auto& names = s.mesh().region_names();
  REQUIRE(e.plastic_work.size() == names.size());
  const double half_volume = 0.5 * length * width * thickness;
  for (std::size_t k = 0; k < 2; ++k) {
    const std::size_t r = static_cast<std::size_t>(s.mesh().region(k == 0 ? "soft" : "hard"));
    INFO(names[r]);
    const double p = 2.0 / 3.0 * (eps - yield[k] / (2.0 * mu));
    REQUIRE(p > 0.0);
    CHECK(e.plastic_work[r] == Approx(yield[k] * p * half_volume).epsilon(1e-9));
    const double w = 0.5 * bulk * eps * eps + mu * 2.0 / 3.0 * std::pow(eps - 1.5 * p, 2);
    CHECK(e.strain_energy[r] == Approx(w * half_volume).epsilon(1e-9));
  }
  // the parts add up to the totals ("all" is empty here)
  auto sum = [](const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); };
  CHECK(sum(e.plastic_work) == Approx(s.plastic_work()).epsilon(1e-12));
  CHECK(sum(e.strain_energy) == Approx(s.strain_energy()).epsilon(1e-12));
  CHECK(s.max_equivalent_plastic_strain() ==
        Approx(2.0 / 3.0 * (eps - yield[0] / (2.0 * mu))).epsilon(1e-9));
}
