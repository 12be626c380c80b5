// Parallel schemes with the participants of one process on threads (coupling.concurrent):
// persistent workers, errors that name the participant. (The same bytes as one after the other,
// for a whole run: tests/coupling/run/test_parallel_run.cpp.)
//   y1' = -a1 y1 + b1 y2,  y2' = -a2 y2 + b2 y1  (ode_participant.hpp)
#include <catch2/catch.hpp>

#include <fstream>
#include <sstream>
#include <thread>

#include "ode_participant.hpp"
#include "partita/coupling/acceleration/iqn_ils.hpp"
#include "partita/coupling/convergence/relative_convergence.hpp"
#include "partita/coupling/explicit_scheme.hpp"
#include "partita/coupling/implicit_scheme.hpp"
#include "partita/interface/error.hpp"

using namespace partita;
using namespace partita::coupling;
using test::OdeParticipant;

namespace {


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


}  // namespace


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
