// Newton convergence on a stiff steel cantilever: a test invariant to the size of the
// load and to the number of load steps, with a floor at the round-off of the internal force;
// failure messages that say what happened (a limit load, an inverted element).
//
// The beam: steel (E = 210 GPa, nu = 0.3, sigma_y = 250 MPa), L = 1 m, b = h = 0.05 m, clamped
// at x = 0, a tip load P (a uniform shear traction on x = L, along -z). First yield at
// M_y = sigma_y b h^2 / 6 at the root: P_y = M_y / L = 5.21 kN; plastic limit load
// P_L = sigma_y b h^2 / (4 L) = 7.81 kN (REFERENCES.md, "Plastic limit loads").
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <string>

#include "nonlinear_test_helpers.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/finite_strain_j2_law.hpp"
#include "partita/fem/j2_plasticity_law.hpp"
#include "partita/fem/linear_elastic_law.hpp"
#include "partita/fem/neo_hooke_law.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;
using partita::fem::test::limit_load_factor;
using partita::fem::test::tip_deflection;

namespace {

constexpr double kE = 210e9, kNu = 0.3, kRho = 7850.0, kSy = 250e6;
constexpr double kL = 1.0, kB = 0.05, kH = 0.05;
const double kYieldLoad = kSy * kB * kH * kH / 6.0 / kL;  // P_y = M_y / L
const double kLimitLoad = kSy * kB * kH * kH / 4.0 / kL;  // P_L = M_p / L

enum class Law { LinearElastic, NeoHooke, J2, J2FiniteStrain };
const char* law_name(Law l) {
  switch (l) {
    case Law::LinearElastic:
      return "linear-elastic";
    case Law::NeoHooke:
      return "neo-hooke";
    case Law::J2:
      return "j2-plasticity";
    default:
      return "j2-plasticity-finite-strain";
  }
}

std::shared_ptr<const MaterialLaw> make_law(Law l, double hardening = 0.0) {
  switch (l) {
    case Law::LinearElastic:
      return std::make_shared<LinearElasticLaw>(Material{kE, kNu, kRho});
    case Law::NeoHooke:
      return std::make_shared<NeoHookeLaw>(kE, kNu, kRho);
    case Law::J2:
      return std::make_shared<J2PlasticityLaw>(kE, kNu, kRho,
                                               HardeningCurve::linear(kSy, hardening));
    default:
      return std::make_shared<FiniteStrainJ2Law>(kE, kNu, kRho,
                                                 HardeningCurve::linear(kSy, hardening));
  }
}

// 10 x 1 x 2 Hex20 (two elements through the depth h: the 3-point rules of the two halves
// integrate a fully plastic section's moment exactly), or the same cells of Hex8.
Model cantilever(Law l, double tip_load, ElementType type = ElementType::Hex20) {
  Model m(make_box_mesh({Vec3::Zero(), Vec3(kL, kB, kH), {10, 1, 2}, type}));
  m.set_material_law(make_law(l));
  m.fix("xmin");
  // P as a uniform shear traction on the end face, ramped with time
  m.add_traction("xmax", Vec3(0.0, 0.0, -tip_load / (kB * kH)), [](double t) { return t; });
  return m;
}

// Solves with the default Newton options in `steps` load steps; returns the tip deflection.
double solve(Law l, double tip_load, int steps, ElementType type = ElementType::Hex20) {
  SolverOptions opt;
  opt.newton.load_steps = steps;
  StructuralSolver s(cantilever(l, tip_load, type), opt);
  s.step_static(1.0);
  return tip_deflection(s);
}

}  // namespace

TEST_CASE("newton: a steel cantilever converges with the defaults from 1 mN to 4 kN, every law",
          "[fem][nonlinear][newton]") {
  REQUIRE(4e3 < kYieldLoad);  // all loads below first yield
  for (Law l : {Law::LinearElastic, Law::NeoHooke, Law::J2, Law::J2FiniteStrain}) {
    for (double p : {1e-3, 1.0, 100.0, 4e3}) {
      for (int steps : {1, 10}) {
        INFO(law_name(l) << ", tip load " << p << " N, " << steps << " load steps");
        double w = 0.0;
        REQUIRE_NOTHROW(w = solve(l, p, steps));
        // Euler-Bernoulli P L^3 / (3 E I), plus Timoshenko's shear term (+0.2 % at L/h = 20)
        const double eb = p * kL * kL * kL / (3.0 * kE * kB * kH * kH * kH / 12.0);
        CHECK(w / eb == Approx(1.0).margin(0.02));
      }
    }
  }
}

TEST_CASE("newton: a steel cantilever converges in 100 load steps from 1 mN to 4 kN, every law",
          "[fem][nonlinear][newton][slow]") {
  for (Law l : {Law::LinearElastic, Law::NeoHooke, Law::J2, Law::J2FiniteStrain}) {
    for (double p : {1e-3, 1.0, 100.0, 4e3}) {
      INFO(law_name(l) << ", tip load " << p << " N, 100 load steps");
      CHECK_NOTHROW(solve(l, p, 100));
    }
  }
}

TEST_CASE("newton: the default Hex8 of the nonlinear path converges on the steel cantilever",
          "[fem][nonlinear][newton]") {
  for (Law l : {Law::NeoHooke, Law::J2, Law::J2FiniteStrain}) {
    for (double p : {1e-3, 100.0, 4e3}) {
      for (int steps : {1, 10}) {
        INFO(law_name(l) << ", tip load " << p << " N, " << steps << " load steps, Hex8");
        CHECK_NOTHROW(solve(l, p, steps, ElementType::Hex8));
      }
    }
  }
}

TEST_CASE("newton: at small loads the four laws give the same tip deflection to 1e-6",
          "[fem][nonlinear][newton]") {
  // at P <= 1 N the rotations (<= 5e-6) and strains (<= 2e-7) are far too small for the
  // geometric and material nonlinearity to show at 1e-6: the finite-strain laws reduce to
  // Hooke's. At 1 mN (strains ~ 2e-10) the laws see F = I + grad u rounded to eps = 2.2e-16, a
  // relative error of ~1e-6 of the strain at each point: there they agree to that round-off
  // (1e-5), not to 1e-6.
  for (double p : {0.1, 1.0, 1e-3}) {
    const double tol = p < 0.01 ? 1e-5 : 1e-6;
    const double w0 = solve(Law::LinearElastic, p, 1);
    for (Law l : {Law::NeoHooke, Law::J2, Law::J2FiniteStrain}) {
      for (int steps : {1, 10}) {
        INFO(law_name(l) << ", tip load " << p << " N, " << steps << " load steps");
        CHECK(std::abs(solve(l, p, steps) / w0 - 1.0) < tol);
      }
    }
  }
}

TEST_CASE(
    "newton: a perfectly plastic bar loaded 20 % above its limit load stops with the "
    "limit-load message at the limit's load factor, and below it converges",
    "[fem][nonlinear][newton][limit]") {
  // a bar in uniaxial tension (symmetry planes), sigma = P / A everywhere: it carries at most
  // P_L = sigma_y A, and yields all at once there
  auto bar = [](Law l, double load) {
    Model m(make_box_mesh({Vec3::Zero(), Vec3(1.0, 0.1, 0.1), {4, 1, 1}, ElementType::Hex8}));
    m.set_material_law(make_law(l));
    m.fix("xmin", {0});
    m.fix("ymin", {1});
    m.fix("zmin", {2});
    m.add_traction("xmax", Vec3(load / 0.01, 0.0, 0.0), [](double t) { return t; });
    return m;
  };
  const double limit = kSy * 0.01;
  for (Law l : {Law::J2, Law::J2FiniteStrain}) {
    INFO(law_name(l));
    SolverOptions opt;
    opt.newton.load_steps = 10;
    {
      StructuralSolver s(bar(l, 0.9 * limit), opt);
      CHECK_NOTHROW(s.step_static(1.0));
    }
    StructuralSolver s(bar(l, 1.2 * limit), opt);
    std::string what;
    const auto reached = limit_load_factor(s, what);
    INFO(what);
    REQUIRE(reached.has_value());
    // P_L / (1.2 P_L) = 0.8333, approached from below to the smallest increment, 0.1 / 2^8
    // (the finite-strain law: its Kirchhoff stress reaches sigma_y, the nominal stress a
    // little less: within 1 % of the small-strain value)
    const double lambda = *reached;
    CHECK(lambda <= 1.0 / 1.2 + 1e-12);
    CHECK(lambda > 1.0 / 1.2 - (l == Law::J2 ? 1e-3 : 1e-2));
  }
}

// The cantilever of the limit-load tests: the Hex20 cells graded towards the root (x = L s^2:
// the first element 10 mm long, so that the hinge can form at the root instead of being spread
// over a 0.1 m element, whose farthest Gauss section must also reach M_p: P = M_p / (L - 0.089)
// = 1.10 P_L), and a root that holds only u_x on the root face, u_y on its line y = b/2 and
// u_z on its line z = h/2 (the section stays plane, the rigid-body motions are held, and its
// lateral contraction is free, symmetric about those lines). The clamped root of cantilever()
// holds the contraction as well: with u_y = u_z = 0 on the face a J2 material there cannot
// flow (plastic flow keeps the volume) and sigma_xx is not bounded by sigma_y; that model
// converged at 1.2 P_L (uniform mesh) and collapsed at 1.09 P_L (graded).
Model cantilever_free_root(double tip_load) {
  constexpr int kCells = 10;
  Mesh mesh = make_box_mesh({Vec3::Zero(), Vec3(kL, kB, kH), {kCells, 1, 2}, ElementType::Hex20});
  // node x = k L / (2 n): corners (k even) to L (k / 2n)^2, mid-edge nodes midway between them
  auto corner = [](int k) { return kL * std::pow(static_cast<double>(k) / (2 * kCells), 2); };
  for (std::size_t i = 0; i < mesh.num_nodes(); ++i) {
    Vec3 x = mesh.node(i);
    const int k = static_cast<int>(std::lround(x.x() / kL * 2 * kCells));
    x.x() = k % 2 == 0 ? corner(k) : 0.5 * (corner(k - 1) + corner(k + 1));
    mesh.set_node(i, x);
  }
  auto on_root_line = [](int axis, double at) {
    return [axis, at](const Vec3& x) {
      return std::abs(x.x()) < 1e-12 && std::abs(x[axis] - at) < 1e-12;
    };
  };
  mesh.add_node_set_where("root_y_mid", on_root_line(1, 0.5 * kB));
  mesh.add_node_set_where("root_z_mid", on_root_line(2, 0.5 * kH));
  Model m(std::move(mesh));
  m.set_material_law(make_law(Law::J2));
  m.fix("xmin", {0});
  m.fix("root_y_mid", {1});
  m.fix("root_z_mid", {2});
  m.add_traction("xmax", Vec3(0.0, 0.0, -tip_load / (kB * kH)), [](double t) { return t; });
  return m;
}

TEST_CASE(
    "newton: a steel cantilever loaded 20 % above its plastic limit load stops with the "
    "limit-load message, below it converges",
    "[fem][nonlinear][newton][limit]") {
  // Beam theory (plane stress: the section free to contract) gives P_L = sigma_y b h^2 / (4 L),
  // a lower bound of the continuum's collapse load (its stress field is admissible; the shear
  // force lowers it by ~0.05 % at L/h = 20). The continuum's hinge is a short zone whose
  // lateral contraction the elastic beam beside it restrains: at most as in plane strain across
  // the width, sigma_xx = 2/sqrt(3) sigma_y, i.e. P <= 2/sqrt(3) P_L = 1.155 P_L (a wide beam's
  // limit). The FE collapse load (a displacement model: an upper bound of the continuum's) must
  // lie between: measured 1.058 P_L. At 1.2 P_L, above both, Newton stops with the limit-load
  // message and the largest load factor it reached; at 0.97 P_L it converges and yields.
  SolverOptions opt;
  opt.newton.load_steps = 10;
  {
    StructuralSolver s(cantilever_free_root(0.97 * kLimitLoad), opt);
    REQUIRE_NOTHROW(s.step_static(1.0));
    CHECK(s.equivalent_plastic_strain().maxCoeff() > 0.0);  // above first yield
  }
  StructuralSolver s(cantilever_free_root(1.2 * kLimitLoad), opt);
  std::string what;
  const auto lambda = limit_load_factor(s, what);
  INFO(what);
  REQUIRE(lambda.has_value());
  const double collapse = 1.2 * *lambda;  // in units of P_L
  CHECK(collapse >= 1.0 - 1e-3);  // the smallest load increment: 1.2 * 0.1 / 2^8 = 5e-4
  CHECK(collapse <= 2.0 / std::sqrt(3.0));
}

TEST_CASE("newton: the clamped steel cantilever below its plastic limit load converges and yields",
          "[fem][nonlinear][newton][limit]") {
  for (Law l : {Law::J2, Law::J2FiniteStrain}) {
    INFO(law_name(l));
    SolverOptions opt;
    opt.newton.load_steps = 10;
    StructuralSolver s(cantilever(l, 0.9 * kLimitLoad), opt);
    REQUIRE_NOTHROW(s.step_static(1.0));
    CHECK(s.equivalent_plastic_strain().maxCoeff() > 0.0);  // above first yield
  }
}

TEST_CASE("newton: an element turned inside out is named with its position",
          "[fem][nonlinear][newton]") {
  // a Neo-Hooke cube squashed by a prescribed displacement of 1.5 times its height: it is flat
  // at two thirds of the way, and no admissible state exists beyond
  Model m(make_box_mesh({Vec3::Zero(), Vec3::Ones(), {1, 1, 1}, ElementType::Hex8}));
  m.set_material_law(std::make_shared<NeoHookeLaw>(1e6, 0.3, 1000.0));
  m.fix("zmin", {2});
  m.fix("xmin", {0});
  m.fix("ymin", {1});
  m.prescribe("zmax", 2, [](double t) { return -1.5 * t; });
  SolverOptions opt;
  opt.newton.max_cutbacks = 4;
  StructuralSolver s(std::move(m), opt);
  CHECK_THROWS_WITH(s.step_static(1.0),
                    Catch::Contains("element 0 (centre at (0.5, 0.5, 0.5) m) is "
                                    "turned inside out") &&
                        Catch::Contains("Elements turn inside out"));
}

