// The FE adapter's material.model and analysis.integrator keys, chosen from YAML, give the
// physics they name: a one-element bar in uniaxial stress against the 1D closed form of each
// law (tests/inputs/fem/bar_uniaxial.yaml), and the released rod of test_load_table.cpp with a
// Neo-Hooke material under Newmark and central difference against its axial period 4 L / c.
#include <catch2/catch.hpp>

#include "../support/run_command.hpp"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using partita::test::quote;

namespace {

// Runs `partita run CASE --set ...` into a fresh folder; the columns of MONITOR.csv (time first).
std::vector<std::vector<double>> run_case(const std::string& case_file,
                                          const std::vector<std::string>& sets,
                                          const std::string& monitor) {
  static int count = 0;
  const fs::path dir =
      fs::temp_directory_path() /
      ("partita_fem_models_" + std::to_string(::getpid()) + "_" + std::to_string(count++));
  std::string cmd = quote(PARTITA_EXECUTABLE) + " run " +
                    quote((fs::path(PARTITA_SOURCE_DIR) / case_file).string()) + " --output " +
                    quote(dir.string());
  for (const auto& s : sets) cmd += " --set " + quote(s);
  const auto r = partita::test::run_command(cmd);
  INFO(cmd << "\n" << r.output);
  REQUIRE(r.status == 0);
  std::ifstream in(dir / (monitor + ".csv"));
  std::string line;
  std::getline(in, line);  // header
  std::vector<std::vector<double>> columns;
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::string cell;
    for (std::size_t c = 0; std::getline(row, cell, ','); ++c) {
      if (columns.size() <= c) columns.emplace_back();
      columns[c].push_back(std::stod(cell));
    }
  }
  fs::remove_all(dir);
  REQUIRE(!columns.empty());
  return columns;
}

// Root of an increasing function on [lo, hi] by bisection to round-off.
double root(const std::function<double(double)>& g, double lo, double hi) {
  for (int i = 0; i < 200 && hi - lo > 1e-15 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (g(mid) > 0 ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

// Uniaxial stress of a hyperelastic law with principal nominal stresses P1(l1, l2), P2(l1, l2):
// the stretches (l1, l2) with P2 = 0 and P1 = t.
struct Stretches {
  double axial, lateral;
};
Stretches uniaxial(const std::function<double(double, double)>& p1,
                   const std::function<double(double, double)>& p2, double t) {
  auto lateral = [&](double l1) { return root([&](double l2) { return p2(l1, l2); }, 0.2, 2.0); };
  const double l1 = root([&](double a) { return p1(a, lateral(a)) - t; }, 1.0, 3.0);
  return {l1, lateral(l1)};
}

constexpr double kE = 2.5e6, kNu = 0.45, kT = 0.5e6;  // bar_uniaxial.yaml

void check_bar(const std::vector<std::vector<double>>& c, Stretches s) {
  // the tip face is at x = 1: u_x = l1 - 1 at each of its nodes; u_y = 0 at y = 0 and l2 - 1
  // at y = 1, mean (l2 - 1) / 2
  INFO("u_x " << c[1].back() << " (closed form " << s.axial - 1 << "), mean u_y " << c[2].back()
              << " (" << 0.5 * (s.lateral - 1) << ")");
  CHECK(c[1].back() == Approx(s.axial - 1).epsilon(1e-8));
  CHECK(c[2].back() == Approx(0.5 * (s.lateral - 1)).epsilon(1e-8));
}

// Period of the free vibration after t_release from the zero crossings of column 1.
double period_after(const std::vector<std::vector<double>>& c, double t_release) {
  std::vector<double> crossings;
  const auto& t = c[0];
  const auto& u = c[1];
  for (std::size_t i = 1; i < t.size(); ++i)
    if (t[i - 1] > t_release && (u[i - 1] > 0) != (u[i] > 0))
      crossings.push_back(t[i - 1] + (t[i] - t[i - 1]) * u[i - 1] / (u[i - 1] - u[i]));
  REQUIRE(crossings.size() >= 8);
  return 2.0 * (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
}

}  // namespace

TEST_CASE("fem adapter: material.model neo-hooke, a bar in uniaxial stress, closed form",
          "[app][fem-models]") {
  // W = mu/2 (tr C - 3) - mu ln J + lambda/2 ln^2 J: P_i = mu (l_i - 1/l_i) + lambda ln J / l_i
  const double mu = kE / (2 * (1 + kNu)), lambda = kE * kNu / ((1 + kNu) * (1 - 2 * kNu));
  auto p = [&](double li, double j) { return mu * (li - 1 / li) + lambda * std::log(j) / li; };
  const Stretches s = uniaxial([&](double a, double b) { return p(a, a * b * b); },
                               [&](double a, double b) { return p(b, a * b * b); }, kT);
  REQUIRE(s.axial > 1.1);  // a large strain
  check_bar(run_case("tests/inputs/fem/bar_uniaxial.yaml", {}, "tip"), s);
}

TEST_CASE("fem adapter: material.model neo-hooke-decoupled and f-bar hex8, closed form",
          "[app][fem-models][slow]") {
  // W = mu/2 (I1_bar - 3) + kappa/4 (J^2 - 1 - 2 ln J), I1_bar = J^(-2/3) (l1^2 + 2 l2^2):
  // P_i = mu J^(-2/3) (l_i - I1 / (3 l_i)) + kappa/2 (J^2 - 1) / l_i
  const double mu = kE / (2 * (1 + kNu)), kappa = kE / (3 * (1 - 2 * kNu));
  auto p = [&](double li, double l1, double l2) {
    const double j = l1 * l2 * l2, i1 = l1 * l1 + 2 * l2 * l2;
    return mu * std::pow(j, -2.0 / 3.0) * (li - i1 / (3 * li)) + 0.5 * kappa * (j * j - 1) / li;
  };
  const Stretches s = uniaxial([&](double a, double b) { return p(a, a, b); },
                               [&](double a, double b) { return p(b, a, b); }, kT);
  // a homogeneous state: the F-bar element must reproduce it as the plain one does
  for (const char* hex8 : {"full", "f-bar"}) {
    INFO("hex8: " << hex8);
    check_bar(run_case("tests/inputs/fem/bar_uniaxial.yaml",
                       {"participants.bar.material.model=neo-hooke-decoupled",
                        std::string("participants.bar.mesh.hex8=") + hex8},
                       "tip"),
              s);
  }
}

TEST_CASE("fem adapter: material.model j2-plasticity and j2-plasticity-finite-strain, 1D models",
          "[app][fem-models][slow]") {
  const double e = 200e9, nu = 0.3, sy = 250e6, h = 2e9, t = 300e6;
  const std::vector<std::string> steel = {"participants.bar.material.youngs_modulus=200 GPa",
                                          "participants.bar.material.poisson_ratio=0.3",
                                          "participants.bar.material.density=7800",
                                          "participants.bar.material.yield_stress=250 MPa",
                                          "participants.bar.material.hardening_modulus=2 GPa",
                                          "participants.bar.loads[0].traction=[300 MPa, 0, 0]"};
  SECTION("small strain: eps = sigma/E + (sigma - sigma_y)/H, lateral -nu sigma/E - eps_p/2") {
    auto sets = steel;
    sets.push_back("participants.bar.material.model=j2-plasticity");
    const double eps_p = (t - sy) / h;
    check_bar(run_case("tests/inputs/fem/bar_uniaxial.yaml", sets, "tip"),
              {1 + t / e + eps_p, 1 - nu * t / e - 0.5 * eps_p});
  }
  SECTION("finite strain: ln l1 = tau/E + (tau - sigma_y)/H with the Kirchhoff stress tau") {
    auto sets = steel;
    sets.push_back("participants.bar.material.model=j2-plasticity-finite-strain");
    // uniaxial nominal stress t: tau = t l1 (tau = P F^T, P = t e1 (x) e1)
    const double l1 =
        root([&](double l) { return std::log(l) - (t * l / e + (t * l - sy) / h); }, 1.0, 1.2);
    const double tau = t * l1, eps_p = (tau - sy) / h;
    // lateral log strain: -nu tau/E (Hencky elasticity) - eps_p / 2 (isochoric flow)
    const double l2 = std::exp(-nu * tau / e - 0.5 * eps_p);
    const auto c = run_case("tests/inputs/fem/bar_uniaxial.yaml", sets, "tip");
    INFO("u_x " << c[1].back() << " (1D " << l1 - 1 << ")");
    CHECK(c[1].back() == Approx(l1 - 1).epsilon(1e-6));
    CHECK(c[2].back() == Approx(0.5 * (l2 - 1)).epsilon(1e-6));
  }
}

TEST_CASE("fem adapter: analysis.integrator newmark and central-difference on neo-hooke",
          "[app][fem-models][slow]") {
  // rod_release.yaml with a Neo-Hooke rod (nu = 0, strain 5e-6: its linear limit), the load
  // ramped over 2 ms (5 periods: no vibration left), held to 3 ms and released: held
  // elongation F L / (E A) = 2.5e-6 m, then free vibration with T1 = 4 L / c = 0.4 ms
  const std::vector<std::string> neo = {
      "participants.rod.material.model=neo-hooke", "time.end=5.0e-3",
      "participants.rod.loads[0].table=[[0, 0], [2.0e-3, 1], [3.0e-3, 1], [3.000001e-3, 0]]"};
  auto cd = neo;
  cd.insert(cd.end(), {"participants.rod.analysis.integrator=central-difference",
                       "participants.rod.analysis.mass=lumped", "time.window=1.0e-6"});
  for (const auto& sets : {neo, cd}) {
    const auto c = run_case("tests/inputs/fem/rod_release.yaml", sets, "tip");
    std::size_t hold = 0;
    while (c[0][hold] < 2.9e-3) ++hold;
    const double period = period_after(c, 3.0e-3);
    INFO(sets.back() << ": held " << c[1][hold] << " m, period " << period << " s");
    CHECK(c[1][hold] == Approx(2.5e-6).epsilon(0.03));
    CHECK(period == Approx(4.0 * 0.5 / std::sqrt(200.0e9 / 8000.0)).epsilon(0.01));
  }
}
