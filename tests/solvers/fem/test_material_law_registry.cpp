// The material-law registry: every built-in law is built from its declared parameters, keeps
// the contract of a law (its name, its density, a stress-free rest state, a tangent that is the
// derivative of its stress), and the checks of the parameters state the rule and the value.
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "partita/fem/error.hpp"
#include "partita/fem/material_law_registry.hpp"

using namespace partita::fem;

namespace {

MaterialLawRegistry builtin() {
  MaterialLawRegistry r;
  register_material_laws(r);
  return r;
}

// Steel-like values inside every declared typical range.
MaterialParameters steel() {
  MaterialParameters p;
  p.set("youngs_modulus", 210e9).set("poisson_ratio", 0.3).set("density", 7850.0);
  return p;
}

// P(F) of a law from its rest state (fresh history each call).
Mat3 stress(const MaterialLaw& law, const Mat3& f, Matrix9* tangent = nullptr) {
  std::vector<double> committed(static_cast<std::size_t>(law.state_size())),
      trial(committed.size());
  law.initialise_state(committed);
  MaterialResponse r;
  law.evaluate(f, committed, trial, r);
  if (tangent != nullptr) *tangent = r.tangent;
  return r.stress;
}

}  // namespace

TEST_CASE("material law registry: every built-in law is made from its declared parameters",
          "[fem][material-law-registry]") {
  const MaterialLawRegistry laws = builtin();
  const auto names = laws.names();
  const std::set<std::string> known(names.begin(), names.end());
  for (const char* name : {"linear-elastic", "neo-hooke", "neo-hooke-decoupled", "j2-plasticity",
                           "j2-plasticity-finite-strain"})
    CHECK(known.count(name) == 1);
  for (const auto& entry : laws.entries()) {
    INFO(entry.name);
    // the contract below is that of a law of the isotropic constants (isotropic_parameters())
    if (entry.find("youngs_modulus") == nullptr) continue;
    CHECK(!entry.doc.empty());
    for (const auto& p : entry.parameters) {
      CHECK(!p.doc.empty());
      if (p.default_value) CHECK(p.allows(*p.default_value));
    }
    MaterialParameters p = steel();
    if (entry.find("yield_stress") != nullptr) p.set("yield_stress", 250e6);
    const auto law = entry.create(p);
    REQUIRE(law != nullptr);
    CHECK(law->name() == entry.name);
    CHECK(law->density() == 7850.0);
    // rest is stress-free; the small-strain bulk modulus is E / (3 (1 - 2 nu))
    CHECK(stress(*law, Mat3::Identity()).norm() <= 1e-6);
    CHECK(law->bulk_modulus() == Approx(210e9 / (3.0 * (1.0 - 0.6))).epsilon(1e-12));
    // the tangent at a small elastic strain is the derivative of the stress (central
    // differences, one column per component of F)
    Mat3 f = Mat3::Identity();
    f(0, 0) += 2e-4;
    f(0, 1) += 1e-4;
    Matrix9 a;
    stress(*law, f, &a);
    const double h = 1e-7;
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) {
        Mat3 fp = f, fm = f;
        fp(k, l) += h;
        fm(k, l) -= h;
        const Mat3 dp = (stress(*law, fp) - stress(*law, fm)) / (2.0 * h);
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            CHECK(std::abs(dp(i, j) - a(3 * i + j, 3 * k + l)) <= 1e-5 * a.cwiseAbs().maxCoeff());
      }
  }
}

TEST_CASE("material law registry: parameters out of range, missing or unknown are refused",
          "[fem][material-law-registry]") {
  const MaterialLawRegistry laws = builtin();
  CHECK_THROWS_WITH(laws.get("neo-hook"),
                    Catch::Contains("unknown material law 'neo-hook'") &&
                        Catch::Contains("neo-hooke") && Catch::Contains("j2-plasticity"));
  const auto& neo = laws.get("neo-hooke");
  MaterialParameters p = steel();
  p.set("poisson_ratio", 0.5);  // incompressible: outside the open range
  CHECK_THROWS_WITH(neo.create(p), Catch::Contains("poisson_ratio must be in (-1, 0.5)") &&
                                       Catch::Contains("got 0.5"));
  MaterialParameters missing;
  missing.set("youngs_modulus", 1e6).set("poisson_ratio", 0.3);
  CHECK_THROWS_WITH(neo.create(missing), Catch::Contains("'density'") && Catch::Contains("required"));
  MaterialParameters unknown = steel();
  unknown.set("yield_stress", 1e6);  // not a parameter of an elastic law
  CHECK_THROWS_WITH(neo.create(unknown), Catch::Contains("unknown parameter 'yield_stress'"));
  // J2: the hardening in one of two forms, the yield stress below E
  const auto& j2 = laws.get("j2-plasticity");
  CHECK_THROWS_WITH(j2.create(steel()), Catch::Contains("needs 'yield_stress'"));
  MaterialParameters both = steel();
  both.set("yield_stress", 250e6).set_table("hardening_table", {{0.0, 250e6}, {0.1, 300e6}});
  CHECK_THROWS_WITH(j2.create(both), Catch::Contains("either yield_stress"));
  MaterialParameters too_high = steel();
  too_high.set("yield_stress", 250e9);  // 250 GPa: a unit left out
  CHECK_THROWS_WITH(j2.create(too_high), Catch::Contains("not below Young's modulus"));
  MaterialParameters table = steel();
  table.set_table("hardening_table", {{0.0, 250e6}, {0.1, 300e6}});
  CHECK(j2.create(table) != nullptr);
  // a name registered twice
  MaterialLawRegistry twice = builtin();
  CHECK_THROWS_WITH(twice.add(twice.entries().front()), Catch::Contains("registered twice"));
}

TEST_CASE("material law registry: a program adds a law of its own beside the built-in ones",
          "[fem][material-law-registry]") {
  MaterialLawRegistry laws = builtin();
  // a law known only to this program: linear elasticity with E given in GPa
  MaterialLawEntry entry{"elastic-gpa",
                         "linear elastic, E in GPa",
                         {MaterialParameter::number("youngs_modulus_gpa", "GPa", "E in GPa")
                              .positive()
                              .required()},
                         [&](const MaterialParameters& p) {
                           MaterialParameters si;
                           si.set("youngs_modulus", 1e9 * p.real("youngs_modulus_gpa"))
                               .set("poisson_ratio", 0.3)
                               .set("density", 7850.0);
                           return laws.get("linear-elastic").create(si);
                         }};
  laws.add(entry);
  MaterialParameters p;
  p.set("youngs_modulus_gpa", 210.0);
  const auto law = laws.get("elastic-gpa").create(p);
  const auto reference = laws.get("linear-elastic").create(steel());
  Mat3 f = Mat3::Identity();
  f(2, 2) += 1e-3;
  CHECK((stress(*law, f) - stress(*reference, f)).norm() <= 1e-12 * stress(*reference, f).norm());
}
