// The energy balance of a whole coupled system (the case's energy section, DIR/energy.csv) on two
// test participants with exact books (oscillator_participants.hpp): a damped mass pushed by a
// constant force and held by a massless spring of another participant. Conservation of energy is
// the reference: kinetic + elastic + damping work = initial energy + applied work, so the only
// imbalance is what the coupling creates (an explicit scheme's lag: a fraction of a percent here)
// or what a broken exchange loses.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "../ode_participant.hpp"
#include "../oscillator_participants.hpp"
#include "partita/run/case_run.hpp"
#include "partita/coupling/mapping/nearest_neighbor_mapper.hpp"
#include "partita/interface/error.hpp"

using namespace partita;
using namespace partita::coupling;
using namespace partita::run;

namespace {

namespace fs = std::filesystem;

fs::path base() {
  return fs::temp_directory_path() / ("partita_energy_balance_test_" + std::to_string(::getpid()));
}

fs::path scratch(const std::string& name) {
  fs::path d = base() / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

struct RemoveScratch {
  ~RemoveScratch() {
    std::error_code ec;
    fs::remove_all(base(), ec);
  }
};

// A participant alone whose books are given: an input of power P (work = P t) and a store that
// holds the work plus a discrepancy chosen by the test, D while t < t_bump (a first touch's few
// mJ against a scale of about as much: below the floor) and eps P t^2 / t_end after it (a leak
// that grows to the fraction eps of the work at the end).
class BooksParticipant : public Solver {
 public:
  BooksParticipant(double power, double bump, double bump_until, double leak, double end)
      : p_(power), d_(bump), until_(bump_until), eps_(leak), end_(end) {}
  const std::vector<InterfaceMesh>& meshes() const override { return meshes_; }
  void read(std::string_view, std::string_view, const Eigen::MatrixXd&) override {}
  void write(std::string_view, std::string_view, Eigen::MatrixXd&) override {}
  void advance(double dt) override { t_ += dt; }
  double time() const override { return t_; }
  void save_checkpoint() override { saved_ = t_; }
  void restore_checkpoint() override { t_ = saved_; }
  std::vector<MonitorValue> monitors() const override {
    const double work = p_ * t_;
    const double off = t_ > 0.0 && t_ < until_ ? d_ : eps_ * p_ * t_ * t_ / end_;
    return {{"work", "J", work}, {"stored", "J", work + off}};
  }

 private:
  std::vector<InterfaceMesh> meshes_;
  double p_, d_, until_, eps_, end_, t_ = 0.0, saved_ = 0.0;
};

// A deliberately broken exchange, registered by this test only: the nearest-neighbour mapping
// times `factor`, so what arrives is not what was sent and the audits must say so.
class ScaledMapper final : public Mapper {
 public:
  ScaledMapper(std::unique_ptr<Mapper> inner, double factor)
      : inner_(std::move(inner)), factor_(factor) {}
  void compute(const Mesh& from, const Mesh& to) override {
    inner_->compute(from, to);
    set_meshes(from, to);
  }
  void map(const Eigen::MatrixXd& in, Eigen::MatrixXd& out) const override {
    inner_->map(in, out);
    out *= factor_;
  }
  Constraint constraint() const override { return inner_->constraint(); }
  std::string name() const override { return "test-scaled"; }

 private:
  std::unique_ptr<Mapper> inner_;
  double factor_;
};

Registries registries() {
  Registries r = test::test_registries();
  auto scaled = std::make_shared<config::Spec>("test-scaled", "nearest-neighbor times a factor");
  scaled->string("type", "test-scaled").required();
  scaled->real("factor", "what arrives over what the nearest-neighbor mapping gives").def(0.9);
  r.mappers.add(
      "test-scaled", "nearest-neighbor times a factor (a broken exchange, for this test)",
      [scaled](const MapperContext& c) -> std::unique_ptr<Mapper> {
        return std::make_unique<ScaledMapper>(
            std::make_unique<NearestNeighborMapper>(c.constraint),
            c.config.validated(scaled).real("factor"));
      },
      scaled);
  test::add_oscillator_solvers(r);
  auto spec = std::make_shared<config::Spec>("test-books", "given energy books");
  spec->real("power", "input power").def(1.0);
  spec->real("bump", "discrepancy before bump_until").def(0.0);
  spec->real("bump_until", "end of the bump").def(0.0);
  spec->real("leak", "discrepancy at the end, over the work").def(0.0);
  spec->real("end", "the case's end").def(1.0);
  r.solvers.add(
      "test-books", "given energy books",
      [](const SolverContext& c) -> std::unique_ptr<Solver> {
        return std::make_unique<BooksParticipant>(c.config.real("power"), c.config.real("bump"),
                                                  c.config.real("bump_until"),
                                                  c.config.real("leak"), c.config.real("end"));
      },
      spec);
  return r;
}

// m = 1 kg, k = 100 N/m on each side, c = 0.5 N s/m, f = 2 N, v0 = 1 m/s: E0 = 1/2 m v0^2 = 0.5 J.
std::string oscillator_case(const std::string& force_exchange_extra = "",
                            const std::string& energy_extra = "", double end = 0.5) {
  std::ostringstream s;
  s << "case: oscillators\n"
       "time: {window: 1.0e-4, end: "
    << end
    << "}\n"
       "participants:\n"
       "  mass: {solver: test-mass, mass: 1.0, stiffness: 100, damping: 0.5, force: 2.0, v0: 1.0}\n"
       "  spring: {solver: test-spring, stiffness: 100}\n"
       "coupling:\n"
       "  scheme: explicit-serial\n"
       "  exchanges:\n"
       "    - {data: displacement, from: mass.point, to: spring.point}\n"
       "    - {data: force, from: spring.point, to: mass.point"
    << force_exchange_extra
    << "}\n"
       "energy:\n"
       "  inputs: [mass.applied_work]\n"
       "  stored: [mass.kinetic_energy, mass.elastic_energy, spring.elastic_energy]\n"
       "  dissipated: [mass.damping_work]\n"
    << energy_extra;
  return s.str();
}

struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  std::vector<double> column(const std::string& name) const {
    const auto it = std::find(header.begin(), header.end(), name);
    REQUIRE(it != header.end());
    std::vector<double> c;
    for (const auto& r : rows) c.push_back(r[static_cast<std::size_t>(it - header.begin())]);
    return c;
  }
};

Table read_csv(const fs::path& p) {
  Table t;
  std::ifstream in(p);
  std::string line, cell;
  std::getline(in, line);
  std::stringstream h(line);
  while (std::getline(h, cell, ',')) t.header.push_back(cell);
  while (std::getline(in, line)) {
    std::stringstream r(line);
    std::vector<double> row;
    while (std::getline(r, cell, ',')) row.push_back(std::stod(cell));
    t.rows.push_back(row);
  }
  return t;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Run a case; its energy.csv.
Table run_case(const std::string& name, const std::string& text, RunOptions o = {}) {
  const fs::path dir = scratch(name);
  const fs::path file = dir / "case.yaml";
  std::ofstream(file) << text;
  const fs::path out = !o.resume_dir.empty() ? o.resume_dir : dir / "out";
  if (o.resume_dir.empty()) o.output_dir = out;
  const Registries r = registries();
  CaseRun run(file, r, o);
  run.run();
  return read_csv(out / "energy.csv");
}

double max_abs(const std::vector<double>& v) {
  double m = 0.0;
  for (const double x : v) m = std::max(m, std::abs(x));
  return m;
}

std::string error_of(const std::string& text) {
  const fs::path dir = scratch("error");
  std::ofstream(dir / "case.yaml") << text;
  RunOptions o;
  o.output_dir = dir / "out";
  o.check_only = true;
  const Registries r = registries();
  try {
    CaseRun run(dir / "case.yaml", r, o);
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST_CASE("energy balance: a coupled oscillator closes within 2 %, a scaled exchange does not",
          "[coupling][case][energy]") {
  RemoveScratch cleanup;
  SECTION("the exchange as it is: the balance closes, the coupling's lag is all of the error") {
    const Table t = run_case("plain", oscillator_case());
    REQUIRE(t.header.front() == "time [s]");
    REQUIRE(t.rows.size() == 5001);  // t = 0 and 5000 windows
    const auto error = t.column("energy balance error [-]");
    const auto initial = t.column("initial [J]");
    const auto inputs = t.column("inputs [J]");
    const auto held = t.column("stored + dissipated [J]");
    const auto created = t.column("coupling created [J]");
    CHECK(initial.front() == Approx(0.5).epsilon(1e-12));  // 1/2 m v0^2
    CHECK(error.front() == 0.0);
    INFO("largest |error| " << max_abs(error));
    CHECK(max_abs(error) <= 0.02);
    CHECK(max_abs(error) > 0.0);  // the explicit scheme's lag creates a little
    // the participants' books are exact: what is off is what the coupling created
    double off = 0.0;
    for (std::size_t i = 0; i < t.rows.size(); ++i)
      off = std::max(off, std::abs(held[i] - inputs[i] - initial[i] - created[i]));
    CHECK(off <= 1e-8 * initial.front());  // the CSV's 10 digits
    // the terms add up to the sums
    const auto ke = t.column("stored mass.kinetic_energy [J]");
    const auto damping = t.column("dissipated mass.damping_work [J]");
    CHECK(damping.back() > 0.0);
    CHECK(t.column("input mass.applied_work [J]").back() == inputs.back());
    CHECK(ke.back() + t.column("stored mass.elastic_energy [J]").back() +
              t.column("stored spring.elastic_energy [J]").back() + damping.back() ==
          Approx(held.back()).epsilon(1e-9));  // CSV: 10 digits
  }
  SECTION("the coupling counted as an input: the participants' own books close to round-off") {
    const Table t = run_case("counted", oscillator_case("", "  coupling: counted\n"));
    CHECK(max_abs(t.column("energy balance error [-]")) <= 1e-10);
    CHECK(std::find(t.header.begin(), t.header.end(), "input coupling created [J]") !=
          t.header.end());
  }
  SECTION("work through a prescribed mesh (a driven body's) is an input, not the coupling's") {
    // The mass participant also drives a point at 0.1 m/s (its mesh 'driver', prescribed), which
    // the spring participant reads on its mesh 'probe' (a spring k_p = 1000 N/m to the ground,
    // pushing nothing back: as a driven bow's surface handed to the granules). The work on the
    // probe, 1/2 k_p x^2, did not pass between the two: what the coupling created is the plain
    // run's. Not marked prescribed, the audit counts it: created = plain + the probe's work.
    const auto with_driver = [](const char* prescribed) {
      std::string text = oscillator_case();
      const std::string mass = "damping: 0.5, force: 2.0, v0: 1.0}";
      text.replace(text.find(mass), mass.size(),
                   std::string("damping: 0.5, force: 2.0, v0: 1.0, driver_speed: 0.1, "
                               "driver_prescribed: ") + prescribed + "}");
      const std::string spring = "spring: {solver: test-spring, stiffness: 100}";
      text.replace(text.find(spring), spring.size(),
                   "spring: {solver: test-spring, stiffness: 100, probe_stiffness: 1000}");
      const std::string last_exchange = "to: mass.point}\n";
      text.insert(text.find(last_exchange) + last_exchange.size(),
                  "    - {data: displacement, from: mass.driver, to: spring.probe}\n");
      return text;
    };
    const Table plain = run_case("plain-again", oscillator_case());
    const Table driven = run_case("driven", with_driver("true"));
    CHECK(driven.column("coupling created [J]") == plain.column("coupling created [J]"));
    CHECK(driven.column("energy balance error [-]") == plain.column("energy balance error [-]"));
    const Table counted = run_case("driven-unmarked", with_driver("false"));
    // at t = 0.5 s the probe is at 0.05 m: 1/2 1000 0.05^2 = 1.25 J (the trapezoid is exact)
    const double probe_work = 0.5 * 1000.0 * 0.05 * 0.05;
    CHECK(counted.column("coupling created [J]").back() - plain.column("coupling created [J]").back() ==
          Approx(probe_work).epsilon(1e-6));
  }
  SECTION("forces scaled by 0.9: the balance fails, and the coupling column holds the loss") {
    // The mass feels 0.9 of the spring's pull, the spring stores 1/2 k x^2: the system gains
    // 0.1 * 1/2 k x^2, up to about 0.1 * 1/2 (k / (k + 0.9 k)) * 0.5 J / 0.5 J = 5 % of the scale.
    const Table t = run_case("scaled", oscillator_case(", mapper: {type: test-scaled, factor: 0.9}"));
    const double worst = max_abs(t.column("energy balance error [-]"));
    INFO("largest |error| " << worst);
    CHECK(worst > 0.02);
    CHECK(worst < 0.08);
    // what the error shows is what the coupling created (reported, not counted)
    const Table c = run_case("scaled-counted", oscillator_case(", mapper: {type: test-scaled, factor: 0.9}", "  coupling: counted\n"));
    CHECK(max_abs(c.column("energy balance error [-]")) <= 1e-10);
  }
  SECTION("with a tolerance and on_exceeded: stop the scaled run stops with a diagnosis") {
    try {
      run_case("stop", oscillator_case(", mapper: {type: test-scaled, factor: 0.9}", "  tolerance: 0.02\n  on_exceeded: stop\n"));
      FAIL("the run did not stop");
    } catch (const Error& e) {
      const std::string what = e.what();
      INFO(what);
      CHECK(what.find("the energy balance is off by") != std::string::npos);
      CHECK(what.find("energy.tolerance 0.02") != std::string::npos);
      CHECK(what.find("the coupling created") != std::string::npos);
    }
    // the rows up to the stop are on disk
    const Table t = read_csv(base() / "stop" / "out" / "energy.csv");
    CHECK(t.rows.size() > 1);
    CHECK(std::abs(t.column("energy balance error [-]").back()) > 0.02);
  }
}

TEST_CASE("energy balance: the run's largest error leaves out the windows below the floor",
          "[coupling][case][energy]") {
  RemoveScratch cleanup;
  // 1 W for 1 s in windows of 10 ms; a floor of 0.1 J, which the work passes at 0.1 s. Over the
  // first 50 ms the store is off by 2 mJ, 2 % of the floor (error 0.02 in energy.csv: the floor
  // is the scale there); then it leaks eps t^2 of the work t, error eps t / (1 + eps t), largest
  // at the end: 1e-3 / 1.001.
  const auto books = [](const std::string& energy_extra) {
    return "case: books\n"
           "time: {window: 0.01, end: 1.0}\n"
           "participants:\n"
           "  b: {solver: test-books, power: 1.0, bump: 0.002, bump_until: 0.055, leak: 1.0e-3, "
           "end: 1.0}\n"
           "energy:\n"
           "  inputs: [b.work]\n"
           "  stored: [b.stored]\n" +
           energy_extra;
  };
  const double leak_at_end = 1e-3 / (1.0 + 1e-3);
  SECTION("with a floor: the rows below it are written, not counted, nor held to the tolerance") {
    const fs::path dir = scratch("floor");
    std::ofstream(dir / "case.yaml") << books("  floor: 0.1\n  tolerance: 0.01\n");
    RunOptions o;
    o.output_dir = dir / "out";
    const Registries r = registries();
    CaseRun run(dir / "case.yaml", r, o);
    run.run();
    const Table t = read_csv(o.output_dir / "energy.csv");
    const auto error = t.column("energy balance error [-]");
    const auto time = t.column("time [s]");
    // energy.csv keeps the early rows, over the floor: 0.002 J / 0.1 J
    CHECK(max_abs(error) == Approx(0.02).epsilon(1e-6));
    const RunSummary& s = run.summary();
    CHECK(s.max_energy_balance_error == Approx(leak_at_end).epsilon(1e-9));
    CHECK(s.max_energy_balance_time == Approx(1.0));
    CHECK(s.max_energy_balance_window == 100);
    // t = 0 and the windows to 90 ms hold less than 0.1 J; from 100 ms on they count
    std::size_t below = 0;
    for (const double x : time) below += x < 0.1 - 1e-9;
    CHECK(below == 10);
    CHECK(s.energy_balance_uncounted == static_cast<long>(below));
    CHECK(s.energy_balance_warnings == 0);  // 0.02 > 0.01, but below the floor
  }
  SECTION("without a floor every row counts: the bump over its own 1-5 mJ is the largest") {
    const fs::path dir = scratch("no-floor");
    std::ofstream(dir / "case.yaml") << books("");
    RunOptions o;
    o.output_dir = dir / "out";
    const Registries r = registries();
    CaseRun run(dir / "case.yaml", r, o);
    run.run();
    const RunSummary& s = run.summary();
    // at t = 10 ms: 0.002 J against the store's 0.012 J
    CHECK(s.max_energy_balance_error == Approx(0.002 / 0.012).epsilon(1e-9));
    CHECK(s.max_energy_balance_window == 1);
    CHECK(s.energy_balance_uncounted == 0);
    CHECK(max_abs(read_csv(o.output_dir / "energy.csv").column("energy balance error [-]")) ==
          Approx(s.max_energy_balance_error).epsilon(1e-6));
  }
}

TEST_CASE("energy balance: a resumed run writes the same energy.csv as a run straight through",
          "[coupling][case][energy]") {
  RemoveScratch cleanup;
  const std::string restart = "output: {restart: {at_end: true}}\n";
  run_case("straight", oscillator_case("", restart, 0.02));
  run_case("part", oscillator_case("", restart, 0.01));
  const fs::path part = base() / "part" / "out";
  RunOptions o;
  o.resume_dir = part;
  run_case("resumed", oscillator_case("", restart, 0.02), o);
  const std::string straight = read_text(base() / "straight" / "out" / "energy.csv");
  CHECK(!straight.empty());
  CHECK(read_text(part / "energy.csv") == straight);
}

TEST_CASE("energy balance: unknown or unfit terms are clear errors at the key",
          "[coupling][case][energy]") {
  RemoveScratch cleanup;
  std::string c = oscillator_case();
  c.replace(c.find("mass.kinetic_energy"), 19, "mass.kinetic_enrgy");
  std::string e = error_of(c);
  INFO(e);
  CHECK(e.find("case.yaml:") != std::string::npos);
  CHECK(e.find("energy.stored") != std::string::npos);
  CHECK(e.find("reports no quantity 'kinetic_enrgy'") != std::string::npos);
  CHECK(e.find("did you mean 'kinetic_energy'") != std::string::npos);

  c = oscillator_case();
  c.replace(c.find("mass.damping_work"), 17, "mass.x");
  e = error_of(c);
  CHECK(e.find("'mass.x' is in m") != std::string::npos);

  c = oscillator_case();
  c.replace(c.find("[mass.applied_work]"), 19, "[mass.applied_work, mass.applied_work]");
  e = error_of(c);
  CHECK(e.find("named twice") != std::string::npos);

  c = oscillator_case();
  c.replace(c.find("spring.elastic_energy"), 21, "sprin.elastic_energy");
  e = error_of(c);
  CHECK(e.find("unknown participant 'sprin'") != std::string::npos);
  CHECK(e.find("did you mean 'spring'") != std::string::npos);
}

TEST_CASE("energy balance and monitors sampled every N windows: the rows of the run straight "
          "through at the initial state, every N-th window and the last",
          "[coupling][case][energy][monitors]") {
  RemoveScratch cleanup;
  // 0.0205 s of 1e-4 s windows: 205 windows, the last not a multiple of 7
  const auto text = [](const std::string& every) {
    return oscillator_case("", every.empty() ? "" : "  every_windows: " + every + "\n", 0.0205) +
           "monitors:\n  - {name: m, quantities: [mass.kinetic_energy, spring.elastic_energy]" +
           (every.empty() ? "" : ", every_windows: " + every) +
           "}\n  - {name: all, quantities: [mass.kinetic_energy]}\n";
  };
  run_case("each", text(""));
  run_case("sampled", text("7"));
  const auto lines = [](const fs::path& p) {
    std::vector<std::string> v;
    std::istringstream in(read_text(p));
    for (std::string l; std::getline(in, l);) v.push_back(l);
    return v;
  };
  for (const std::string file : {"energy.csv", "m.csv"}) {
    const std::vector<std::string> each = lines(base() / "each" / "out" / file);
    const std::vector<std::string> sampled = lines(base() / "sampled" / "out" / file);
    REQUIRE(each.size() == 1 + 1 + 205);  // the header, t = 0, the windows
    std::vector<std::string> expected = {each[0]};
    for (std::size_t w = 0; w <= 205; ++w)
      if (w % 7 == 0 || w == 205) expected.push_back(each[1 + w]);
    INFO(file);
    CHECK(sampled == expected);
  }
  // a monitor without every_windows keeps its row at every window
  CHECK(read_text(base() / "sampled" / "out" / "all.csv") ==
        read_text(base() / "each" / "out" / "all.csv"));
}
