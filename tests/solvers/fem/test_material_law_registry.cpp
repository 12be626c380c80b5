// The material-law registry: every built-in law is built from its declared parameters, keeps
// the contract of a law (its name, its density, a stress-free rest state, a tangent that is the
// derivative of its stress), and the checks of the parameters state the rule and the value.
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "partita/fem/box_mesher.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/linear_elastic_law.hpp"
#include "partita/fem/material_law_registry.hpp"
#include "partita/fem/model.hpp"

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

TEST_CASE("material law registry: a broken rule between parameters names the parameter, the "
          "cell and the others it reads",
          "[fem][material-law-registry]") {
  const MaterialLawRegistry laws = builtin();
  for (const char* name : {"j2-plasticity", "j2-plasticity-finite-strain"}) {
    INFO(name);
    const auto& j2 = laws.get(name);
    // a table whose second point is at E: the yield stress of row 1, read against E
    MaterialParameters table = steel();
    table.set_table("hardening_table", {{0.0, 250e6}, {0.1, 210e9}});
    auto issue = j2.issue(j2.completed(table));
    REQUIRE(issue.has_value());
    CHECK(issue->parameter == "hardening_table");
    CHECK(issue->row == 1);
    CHECK(issue->column == "yield_stress");
    CHECK(issue->related == std::vector<std::string>{"youngs_modulus"});
    CHECK_THAT(issue->message, Catch::Contains("not below Young's modulus"));
    // the same as an Error from create(), with the message
    CHECK_THROWS_WITH(j2.create(table), Catch::Contains("not below Young's modulus"));
    // neither form: about the parameters as a whole
    issue = j2.issue(j2.completed(steel()));
    REQUIRE(issue.has_value());
    CHECK(issue->parameter.empty());
    CHECK_THAT(issue->message, Catch::Contains("needs 'yield_stress'"));
    // a valid linear hardening: no issue
    MaterialParameters linear = steel();
    linear.set("yield_stress", 250e6);
    CHECK_FALSE(j2.issue(j2.completed(linear)).has_value());
  }
  // a table's cells are checked against their columns' ranges, naming row and column
  const auto& j2 = laws.get("j2-plasticity");
  MaterialParameters negative = steel();
  negative.set_table("hardening_table", {{0.0, 250e6}, {-0.1, 300e6}});
  CHECK_THROWS_WITH(j2.completed(negative), Catch::Contains("hardening_table row 1") &&
                                                Catch::Contains("plastic_strain must be >= 0"));
  MaterialParameters short_row = steel();
  short_row.set_table("hardening_table", {{0.0}});
  CHECK_THROWS_WITH(j2.completed(short_row),
                    Catch::Contains("(plastic_strain, yield_stress)") && Catch::Contains("got one of 1"));
  // the elastic laws have no rules between their parameters
  CHECK_FALSE(laws.get("neo-hooke").issue(steel()).has_value());
}

namespace {

// A law that gives only what every law must (density, bulk modulus, wave speed): its small-strain
// constants are derived from those.
class BareLaw final : public MaterialLaw {
 public:
  BareLaw(double k, double mu, double rho) : k_(k), mu_(mu), rho_(rho) {}
  std::string_view name() const override { return "bare"; }
  double density() const override { return rho_; }
  double dilatational_wave_speed() const override { return std::sqrt((k_ + 4.0 / 3.0 * mu_) / rho_); }
  double bulk_modulus() const override { return k_; }
  void evaluate(const Mat3&, std::span<const double>, std::span<double>,
                MaterialResponse&) const override {}

 private:
  double k_, mu_, rho_;
};

}  // namespace

TEST_CASE("model: one law per region, its small-strain constants a view of the law",
          "[fem][material-law-registry]") {
  const MaterialLawRegistry laws = builtin();
  BoxSpec box;
  box.cells = {2, 1, 1};
  Mesh mesh = make_box_mesh(box);
  mesh.assign_region_where("right", [](const Vec3& c) { return c.x() > 0.5; });

  // a Material is a linear-elastic law: the linear path, the law's constants
  Model model(mesh, Material{70e9, 0.33, 2700.0});
  CHECK(model.is_linear());
  for (int r = 0; r < 2; ++r) {
    CHECK(model.material_law(r) == nullptr);
    REQUIRE(dynamic_cast<const LinearElasticLaw*>(&model.law(r)) != nullptr);
    CHECK(model.material(r).youngs_modulus == 70e9);
    CHECK(model.density(r) == 2700.0);
  }
  // a nonlinear law in one region: the constants it was made of, exactly, there alone
  MaterialParameters p = steel();
  p.set("yield_stress", 250e6);
  model.set_material_law("right", laws.get("j2-plasticity").create(p));
  CHECK_FALSE(model.is_linear());
  const int right = mesh.region("right"), left = 1 - right;
  REQUIRE(model.material_law(right) != nullptr);
  CHECK(model.material_law(right)->name() == "j2-plasticity");
  CHECK(model.material(right).youngs_modulus == 210e9);
  CHECK(model.material(right).poisson_ratio == 0.3);
  CHECK(model.density(right) == 7850.0);
  CHECK(model.material(left).youngs_modulus == 70e9);
  // a linear-elastic law from the registry is the linear path again
  model.set_material_law(laws.get("linear-elastic").create(steel()));
  CHECK(model.is_linear());
  CHECK(model.material(right).youngs_modulus == 210e9);
  // every built-in law of the isotropic constants returns them as given
  for (const auto& entry : laws.entries()) {
    if (entry.find("youngs_modulus") == nullptr) continue;
    INFO(entry.name);
    MaterialParameters q = steel();
    if (entry.find("yield_stress") != nullptr) q.set("yield_stress", 250e6);
    const Material m = entry.create(q)->small_strain_material();
    CHECK(m.youngs_modulus == 210e9);
    CHECK(m.poisson_ratio == 0.3);
    CHECK(m.density == 7850.0);
  }
  // a law that does not know E and nu: from K = E / (3 (1 - 2 nu)) and mu = E / (2 (1 + nu))
  const double e = 5e6, nu = 0.4;
  const BareLaw bare(e / (3 * (1 - 2 * nu)), e / (2 * (1 + nu)), 1200.0);
  const Material m = bare.small_strain_material();
  CHECK(m.youngs_modulus == Approx(e).epsilon(1e-12));
  CHECK(m.poisson_ratio == Approx(nu).epsilon(1e-12));
  CHECK(m.density == 1200.0);
}
