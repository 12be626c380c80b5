// Coupling schemes on two participants that split a linear ODE system (ode_participant.hpp):
//   y1' = -a1 y1 + b1 y2,  y2' = -a2 y2 + b2 y1,  y(0) = (1, 0).
#include <catch2/catch.hpp>

#include <cmath>

#include <Eigen/LU>

#include "ode_participant.hpp"
#include "partita/coupling/acceleration/aitken.hpp"
#include "partita/coupling/acceleration/constant_relaxation.hpp"
#include "partita/coupling/acceleration/iqn_ils.hpp"
#include "partita/coupling/convergence/absolute_convergence.hpp"
#include "partita/coupling/convergence/relative_convergence.hpp"
#include "partita/coupling/explicit_scheme.hpp"
#include "partita/coupling/implicit_scheme.hpp"

using namespace partita;
using namespace partita::coupling;
using test::OdeParticipant;

namespace {

constexpr double a1 = 1.0, b1 = 0.5, a2 = 1.5, b2 = 2.0;

struct Setup {
  std::unique_ptr<Participant> p1, p2;
  std::unique_ptr<Exchange> e12, e21;
  OdeParticipant* s1 = nullptr;
  OdeParticipant* s2 = nullptr;
  Setup(int substeps2 = 1, ReaderSees sees = ReaderSees::linear,
        WriterCombines combines = WriterCombines::average) {
    auto o1 = std::make_unique<OdeParticipant>("y1", "y2", a1, b1, 1.0);
    auto o2 = std::make_unique<OdeParticipant>("y2", "y1", a2, b2, 0.0);
    s1 = o1.get();
    s2 = o2.get();
    p1 = std::make_unique<LocalParticipant>("one", std::move(o1));
    p2 = std::make_unique<LocalParticipant>("two", std::move(o2), Substeps{false, substeps2});
    e12 = std::make_unique<Exchange>("y1", Exchange::End{p1.get(), "point"},
                                     Exchange::End{p2.get(), "point"}, DataSpec{"y1", 1, "m"},
                                     nullptr, sees, combines);
    e21 = std::make_unique<Exchange>("y2", Exchange::End{p2.get(), "point"},
                                     Exchange::End{p1.get(), "point"}, DataSpec{"y2", 1, "m"},
                                     nullptr, sees, combines);
  }
  std::vector<Participant*> participants() { return {p1.get(), p2.get()}; }
  std::vector<Exchange*> exchanges() { return {e12.get(), e21.get()}; }
};

void run(CouplingScheme& scheme, double dt, int windows, int* iterations = nullptr) {
  scheme.initialize();
  int total = 0;
  for (int n = 0; n < windows; ++n) total += scheme.advance(TimeWindow(dt, n, 1)).iterations;
  if (iterations) *iterations = total;
}

// The exact solution at t (fine RK4 on the whole system: an independent integrator).
Eigen::Vector2d exact(double t) {
  Eigen::Matrix2d m;
  m << -a1, b1, b2, -a2;
  Eigen::Vector2d y(1.0, 0.0);
  const int n = 20000;
  const double h = t / n;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d k1 = m * y, k2 = m * (y + 0.5 * h * k1), k3 = m * (y + 0.5 * h * k2),
                          k4 = m * (y + h * k3);
    y += h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  return y;
}

// The monolithic solution of the same discretisation an implicit scheme converges to: each
// scalar advanced exactly with the other one's end-of-window value, both solved together:
//   y1' = e1 y1 + c1 y2',  y2' = e2 y2 + c2 y1'   with e = exp(-a dt), c = (b/a)(1 - e).
Eigen::Vector2d monolithic(double dt, int windows) {
  const double e1 = std::exp(-a1 * dt), e2 = std::exp(-a2 * dt);
  const double c1 = b1 / a1 * (1 - e1), c2 = b2 / a2 * (1 - e2);
  Eigen::Matrix2d m;
  m << 1.0, -c1, -c2, 1.0;
  Eigen::Vector2d y(1.0, 0.0);
  for (int n = 0; n < windows; ++n)
    y = m.partialPivLu().solve(Eigen::Vector2d(e1 * y(0), e2 * y(1)));
  return y;
}

double fitted_order(const std::vector<double>& dts, const std::vector<double>& errors) {
  // least-squares slope of log(error) against log(dt)
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = static_cast<double>(dts.size());
  for (std::size_t i = 0; i < dts.size(); ++i) {
    const double x = std::log(dts[i]), y = std::log(errors[i]);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

std::vector<std::unique_ptr<ConvergenceMeasure>> relative_measures(double limit) {
  std::vector<std::unique_ptr<ConvergenceMeasure>> m;
  m.push_back(std::make_unique<RelativeConvergence>("y1", limit));
  m.push_back(std::make_unique<RelativeConvergence>("y2", limit));
  return m;
}

}  // namespace

TEST_CASE("Explicit schemes converge with order 1 in the window size", "[coupling][scheme]") {
  const Eigen::Vector2d reference = exact(1.0);
  for (bool serial : {true, false}) {
    std::vector<double> dts, errors;
    for (double dt : {0.1, 0.05, 0.025, 0.0125}) {
      Setup s;
      ExplicitScheme scheme(s.participants(), s.exchanges(), serial);
      run(scheme, dt, static_cast<int>(std::lround(1.0 / dt)));
      dts.push_back(dt);
      errors.push_back((Eigen::Vector2d(s.s1->y(), s.s2->y()) - reference).norm());
    }
    const double order = fitted_order(dts, errors);
    INFO((serial ? "explicit-serial" : "explicit-parallel")
         << ": errors " << errors[0] << " " << errors[1] << " " << errors[2] << " " << errors[3]
         << ", order " << order);
    CHECK(std::abs(order - 1.0) < 0.1);
  }
}

TEST_CASE("Implicit schemes reach the monolithic solution to the convergence tolerance",
          "[coupling][scheme]") {
  const double dt = 0.1, limit = 1e-10;
  const int windows = 10;
  const Eigen::Vector2d mono = monolithic(dt, windows);
  struct Variant {
    const char* name;
    bool serial;
    std::function<std::unique_ptr<Acceleration>()> acceleration;
  };
  const std::vector<Variant> variants = {
      {"serial, none", true, [] { return nullptr; }},
      {"serial, constant 0.7", true, [] { return std::make_unique<ConstantRelaxation>(0.7); }},
      {"serial, aitken", true, [] { return std::make_unique<Aitken>(0.5); }},
      {"serial, iqn-ils", true, [] { return std::make_unique<IqnIls>(IqnIls::Options{}); }},
      {"parallel, none", false, [] { return nullptr; }},
      {"parallel, aitken", false, [] { return std::make_unique<Aitken>(0.5); }},
      {"parallel, iqn-ils", false, [] { return std::make_unique<IqnIls>(IqnIls::Options{}); }},
  };
  for (const auto& v : variants) {
    Setup s;
    ImplicitScheme::Options o;
    o.serial = v.serial;
    o.on_max_iterations = OnMaxIterations::error;
    ImplicitScheme scheme(s.participants(), s.exchanges(), o, relative_measures(limit),
                          v.acceleration());
    int iterations = 0;
    run(scheme, dt, windows, &iterations);
    const Eigen::Vector2d y(s.s1->y(), s.s2->y());
    INFO(v.name << ": " << iterations << " iterations, error " << (y - mono).norm());
    // relative changes of 1e-10 per iteration of a contraction with factor ~0.1: error ~1e-10 |y|
    CHECK((y - mono).norm() < 20 * limit * mono.norm());
    // and an explicit scheme is much further off (the test can tell)
    CHECK((monolithic(dt, windows) - exact(1.0)).norm() > 1e-4);
  }
}

TEST_CASE("Subcycling: linear interpolation reproduces a linear-in-time input at every substep",
          "[coupling][scheme][subcycling]") {
  // participant one writes f(t) = 1 + 2 t (values and window 0.25 are exact in binary);
  // participant two takes 4 substeps per window and must read f(t_{n,k}) at each.
  Setup s(4, ReaderSees::linear);
  s.s1->output_ = [](double t) { return 1.0 + 2.0 * t; };
  ExplicitScheme scheme(s.participants(), s.exchanges(), true);
  run(scheme, 0.25, 3);
  REQUIRE(s.s2->reads_.size() == 12);
  for (int i = 0; i < 12; ++i) CHECK(s.s2->reads_[i] == 1.0 + 2.0 * 0.0625 * (i + 1));
  for (double dt : s.s2->steps_) CHECK(dt == 0.0625);

  // constant: the newest value at every substep
  Setup c(4, ReaderSees::constant);
  c.s1->output_ = [](double t) { return 1.0 + 2.0 * t; };
  ExplicitScheme scheme_c(c.participants(), c.exchanges(), true);
  run(scheme_c, 0.25, 2);
  REQUIRE(c.s2->reads_.size() == 8);
  for (int i = 0; i < 8; ++i) CHECK(c.s2->reads_[i] == 1.0 + 2.0 * 0.25 * (i / 4 + 1));
}

TEST_CASE(
    "Subcycling: averaging a constant output returns it exactly, last returns the last substep",
    "[coupling][scheme][subcycling]") {
  for (int m : {3, 7, 1000}) {
    Setup s(m, ReaderSees::linear, WriterCombines::average);
    s.s2->output_ = [](double) { return 0.1 + 0.2; };  // not a binary fraction
    ExplicitScheme scheme(s.participants(), s.exchanges(), true);
    run(scheme, 0.1, 2);
    CHECK(s.e21->combined()(0, 0) == 0.1 + 0.2);
  }
  Setup s(5, ReaderSees::linear, WriterCombines::last);
  s.s2->output_ = [](double t) { return t; };
  ExplicitScheme scheme(s.participants(), s.exchanges(), true);
  run(scheme, 0.5, 1);
  CHECK(s.e21->combined()(0, 0) == Approx(0.5).epsilon(1e-15));
  // average of a linear output over m substep ends: f(t_n + (m+1)/(2m) dt)
  Setup avg(4, ReaderSees::linear, WriterCombines::average);
  avg.s2->output_ = [](double t) { return t; };
  ExplicitScheme scheme_avg(avg.participants(), avg.exchanges(), true);
  run(scheme_avg, 1.0, 1);
  CHECK(avg.e21->combined()(0, 0) == Approx(5.0 / 8.0).epsilon(1e-15));
}

TEST_CASE(
    "Checkpoint/restore through an implicit window leaves a participant as one clean run of the "
    "window",
    "[coupling][scheme][checkpoint]") {
  Setup s;
  ImplicitScheme::Options o;
  ImplicitScheme scheme(s.participants(), s.exchanges(), o, relative_measures(1e-12),
                        std::make_unique<Aitken>(0.5));
  scheme.initialize();
  const WindowReport r = scheme.advance(TimeWindow(0.1, 0, 1));
  REQUIRE(r.iterations > 3);  // it did iterate and restore
  // The same window once, from the initial state, with the input of the accepted iteration:
  OdeParticipant fresh("y1", "y2", a1, b1, 1.0);
  fresh.read("point", "y2", Eigen::MatrixXd::Constant(1, 1, s.s1->input()));
  fresh.advance(0.1);
  CHECK(fresh.y() == s.s1->y());  // bit for bit
  CHECK(fresh.time() == s.s1->time());
}

TEST_CASE("Implicit scheme: max_iterations with policy error stops with a clear error",
          "[coupling][scheme]") {
  Setup s;
  ImplicitScheme::Options o;
  o.max_iterations = 2;
  o.on_max_iterations = OnMaxIterations::error;
  ImplicitScheme scheme(s.participants(), s.exchanges(), o, relative_measures(1e-14), nullptr);
  scheme.initialize();
  try {
    scheme.advance(TimeWindow(0.1, 0, 1));
    FAIL("no error");
  } catch (const Error& e) {
    CHECK_THAT(e.what(), Catch::Contains("did not converge in 2 iterations") &&
                             Catch::Contains("max_iterations"));
  }
  o.on_max_iterations = OnMaxIterations::accept;
  Setup t;
  ImplicitScheme accepting(t.participants(), t.exchanges(), o, relative_measures(1e-14), nullptr);
  accepting.initialize();
  const WindowReport r = accepting.advance(TimeWindow(0.1, 0, 1));
  CHECK(r.iterations == 2);
  CHECK_FALSE(r.converged);
}
