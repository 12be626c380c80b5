// Parallel schemes with the participants of one process on threads (coupling.concurrent): the
// same bytes as one after the other, persistent workers, errors that name the participant.
//   y1' = -a1 y1 + b1 y2,  y2' = -a2 y2 + b2 y1  (ode_participant.hpp)
#include <catch2/catch.hpp>

#include <fstream>
#include <sstream>
#include <thread>

#include "ode_participant.hpp"
#include "partita/coupling/acceleration/iqn_ils.hpp"
#include "partita/coupling/case_run.hpp"
#include "partita/coupling/convergence/relative_convergence.hpp"
#include "partita/coupling/explicit_scheme.hpp"
#include "partita/coupling/implicit_scheme.hpp"
#include "partita/interface/error.hpp"

using namespace partita;
using namespace partita::coupling;
using test::OdeParticipant;

namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  fs::path d = fs::temp_directory_path() /
               ("partita_threads_test_" + std::to_string(::getpid())) / name;
  fs::create_directories(d);
  return d;
}

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The ODE participant that notes the thread of each step and fails from t = fail_at on.
class ThreadedOde : public OdeParticipant {
 public:
  ThreadedOde(std::string writes, std::string reads, double a, double b, double y0,
              double fail_at = INFINITY)
      : OdeParticipant(std::move(writes), std::move(reads), a, b, y0), fail_at_(fail_at) {}
  void advance(double dt) override {
    threads.push_back(std::this_thread::get_id());
    if (time() + 0.5 * dt >= fail_at_)
      throw Error("test-ode: diverged at t = " + std::to_string(time()));
    OdeParticipant::advance(dt);
  }
  std::vector<std::thread::id> threads;

 private:
  double fail_at_;
};

struct Pair {
  std::unique_ptr<Participant> p1, p2;
  std::unique_ptr<Exchange> e12, e21;
  ThreadedOde* s1 = nullptr;
  ThreadedOde* s2 = nullptr;
  explicit Pair(double fail1 = INFINITY, double fail2 = INFINITY) {
    auto o1 = std::make_unique<ThreadedOde>("y1", "y2", 1.0, 0.5, 1.0, fail1);
    auto o2 = std::make_unique<ThreadedOde>("y2", "y1", 1.5, 2.0, 0.0, fail2);
    s1 = o1.get();
    s2 = o2.get();
    p1 = std::make_unique<LocalParticipant>("one", std::move(o1));
    p2 = std::make_unique<LocalParticipant>("two", std::move(o2), Substeps{false, 3});
    e12 = std::make_unique<Exchange>("y1", Exchange::End{p1.get(), "point"},
                                     Exchange::End{p2.get(), "point"}, DataSpec{"y1", 1, "m"},
                                     nullptr);
    e21 = std::make_unique<Exchange>("y2", Exchange::End{p2.get(), "point"},
                                     Exchange::End{p1.get(), "point"}, DataSpec{"y2", 1, "m"},
                                     nullptr);
  }
  std::vector<Participant*> participants() { return {p1.get(), p2.get()}; }
  std::vector<Exchange*> exchanges() { return {e12.get(), e21.get()}; }
};

// Windows 0, 1, ... of 0.1 s; the message of the error that stopped them ("" if none).
std::string run_windows(CouplingScheme& scheme, int windows) {
  scheme.initialize();
  try {
    for (int n = 0; n < windows; ++n) scheme.advance(TimeWindow(0.1, n, 1));
  } catch (const Error& e) {
    return e.what();
  }
  return {};
}

const std::string ode_case = R"(case: ode-threads
time: {window: 0.1, end: 2.0}
participants:
  one: {solver: test-ode, writes: y1, reads: y2, a: 1.0, b: 0.5, y0: 1.0}
  two: {solver: test-ode, writes: y2, reads: y1, a: 1.5, b: 2.0}
coupling:
  scheme: SCHEME
  concurrent: CONCURRENT
  substeps: {two: 3}
  exchanges:
    - {data: y1, from: one.point, to: two.point}
    - {data: y2, from: two.point, to: one.point}
IMPLICIT
monitors:
  - {name: state, quantities: [one.y, two.y]}
output: {every: 0.5}
)";

const std::string implicit_keys = R"(  convergence:
    - {type: relative, data: y1, limit: 1.0e-9}
    - {type: relative, data: y2, limit: 1.0e-9}
  acceleration: {type: iqn-ils, initial_relaxation: 0.5})";

std::string replaced(std::string text, const std::string& what, const std::string& by) {
  text.replace(text.find(what), what.size(), by);
  return text;
}

}  // namespace

TEST_CASE("Parallel schemes on threads write the bytes of the participants one after the other",
          "[coupling][scheme][threads]") {
  const Registries r = test::test_registries();
  for (const std::string scheme : {"explicit-parallel", "implicit-parallel"}) {
    std::string text = replaced(ode_case, "SCHEME", scheme);
    text = replaced(text, "IMPLICIT", scheme == "implicit-parallel" ? implicit_keys : "");
    std::vector<std::string> files[2];
    for (const bool concurrent : {true, false}) {
      const fs::path dir = scratch(scheme + (concurrent ? "_threads" : "_one_by_one"));
      const fs::path file = dir / "case.yaml";
      std::ofstream(file) << replaced(text, "CONCURRENT", concurrent ? "true" : "false");
      RunOptions o;
      o.output_dir = dir / "out";
      CaseRun run(file, r, o);
      run.run();
      INFO(scheme << (concurrent ? " on threads" : " one by one"));
      CHECK(run.summary().windows == 20);
      // threads only where asked: one OpenMP share per participant, none one by one
      CHECK(run.scheme().concurrent_omp_threads().size() == (concurrent ? 2u : 0u));
      CHECK(run.summary().overlap_seconds >= 0.0);
      for (const char* f : {"coupling.csv", "state.csv"})
        files[concurrent ? 0 : 1].push_back(read_bytes(o.output_dir / f));
    }
    INFO(scheme);
    REQUIRE(files[0].size() == 2);
    CHECK(files[0][0].size() > 100);  // a header and 20 rows
    CHECK(files[0][0] == files[1][0]);  // coupling.csv
    CHECK(files[0][1] == files[1][1]);  // state.csv (the monitors)
  }
}

TEST_CASE("Parallel schemes on threads: a persistent worker per extra participant",
          "[coupling][scheme][threads]") {
  Pair s;
  ImplicitScheme::Options o;
  o.serial = false;
  std::vector<std::unique_ptr<ConvergenceMeasure>> m;
  m.push_back(std::make_unique<RelativeConvergence>("y1", 1e-9));
  m.push_back(std::make_unique<RelativeConvergence>("y2", 1e-9));
  ImplicitScheme scheme(s.participants(), s.exchanges(), o, std::move(m),
                        std::make_unique<IqnIls>(IqnIls::Options{}));
  REQUIRE(scheme.concurrent());  // the default of a parallel scheme
  CHECK(run_windows(scheme, 5).empty());
  REQUIRE(s.s2->threads.size() > 15);  // 5 windows, 3 substeps, several iterations each
  // the first participant on the calling thread, the second on one other thread throughout
  for (const auto& id : s.s1->threads) CHECK(id == std::this_thread::get_id());
  const std::thread::id worker = s.s2->threads.front();
  CHECK(worker != std::this_thread::get_id());
  for (const auto& id : s.s2->threads) CHECK(id == worker);
  // joined: the next window starts a new worker (its id may be the old one's, reused)
  scheme.stop_threads();
  s.s2->threads.clear();
  scheme.advance(TimeWindow(0.1, 5, 1));
  REQUIRE_FALSE(s.s2->threads.empty());
  CHECK(s.s2->threads.front() != std::this_thread::get_id());
}

TEST_CASE("Parallel schemes on threads: a participant that throws in window 3 is named, no hang",
          "[coupling][scheme][threads][errors]") {
  const double t3 = 0.3;  // window 3 (0-based) starts here
  for (const bool concurrent : {true, false}) {
    INFO((concurrent ? "on threads" : "one by one"));
    {  // the second participant (on a worker) fails; the first finishes the window
      Pair s(INFINITY, t3);
      ExplicitScheme scheme(s.participants(), s.exchanges(), false);
      scheme.set_concurrent(concurrent);
      CHECK_THAT(run_windows(scheme, 10),
                 Catch::StartsWith("participant 'two' failed: test-ode: diverged at t = 0.3"));
      CHECK(s.s1->time() == Approx(0.4));
    }
    {  // the first participant (on the calling thread) fails
      Pair s(t3, INFINITY);
      ExplicitScheme scheme(s.participants(), s.exchanges(), false);
      scheme.set_concurrent(concurrent);
      CHECK_THAT(run_windows(scheme, 10),
                 Catch::StartsWith("participant 'one' failed: test-ode: diverged at t = 0.3"));
      if (concurrent) CHECK(s.s2->time() == Approx(0.4));  // the other finished the window
    }
    // both fail: the first by participant order, whichever thread is faster
    for (int repeat = 0; repeat < 5; ++repeat) {
      Pair s(t3, t3);
      ImplicitScheme::Options o;
      o.serial = false;
      std::vector<std::unique_ptr<ConvergenceMeasure>> m;
      m.push_back(std::make_unique<RelativeConvergence>("y1", 1e-9));
      ImplicitScheme scheme(s.participants(), s.exchanges(), o, std::move(m), nullptr);
      scheme.set_concurrent(concurrent);
      CHECK_THAT(run_windows(scheme, 10), Catch::StartsWith("participant 'one' failed"));
    }
  }
}

TEST_CASE("coupling.concurrent on a serial scheme is a clear error at the key",
          "[coupling][case][errors]") {
  const Registries r = test::test_registries();
  std::string text = replaced(ode_case, "SCHEME", "explicit-serial");
  text = replaced(replaced(text, "IMPLICIT", ""), "CONCURRENT", "true");
  const fs::path dir = scratch("serial_concurrent");
  std::ofstream(dir / "case.yaml") << text;
  RunOptions o;
  o.output_dir = dir / "out";
  o.check_only = true;
  try {
    CaseRun run(dir / "case.yaml", r, o);
    FAIL("no error");
  } catch (const Error& e) {
    CHECK_THAT(std::string(e.what()), Catch::Contains("coupling.concurrent") &&
                                          Catch::Contains("explicit-serial") &&
                                          Catch::Contains("explicit-parallel and implicit-parallel"));
  }
  // false is harmless on a serial scheme (one after the other is what it does)
  std::ofstream(dir / "case.yaml") << replaced(text, "concurrent: true", "concurrent: false");
  CHECK_NOTHROW(CaseRun(dir / "case.yaml", r, o));
}
