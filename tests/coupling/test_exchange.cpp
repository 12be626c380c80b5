// A participant's side of a window (LocalParticipant over an Exchange's values): the substep
// average and the time interpolation give, bit for bit, the numbers of their plain formulas (each operation is IEEE-rounded, so any correct evaluation of the same
// operations in the same order must agree to the last bit, whatever vector width it uses); an
// exchange mapped in the receiver's process names the sender's values whose mapping the
// receiver holds; the audit's fused totals follow their formula. (The audits of a run:
// tests/coupling/run/test_audits.cpp.)
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

#include "partita/coupling/elementwise.hpp"
#include "array_solver.hpp"
#include "ode_participant.hpp"
#include "partita/coupling/exchange.hpp"
#include "partita/coupling/mapping/nearest_neighbor_mapper.hpp"
#include "partita/interface/state_archive.hpp"
#include "partita/interface/error.hpp"

using namespace partita;
using namespace partita::coupling;
using test::ArraySolver;

namespace {


bool same_bits(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<std::size_t>(a.size())) == 0;
}

// Values of every kind the interface carries: zeros of both signs (no contact), small and large
// magnitudes of both signs.
Eigen::MatrixXd values(Eigen::Index n, std::mt19937& g) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> e(-30, 30), kind(0, 5);
  Eigen::MatrixXd v(n, 3);
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    const int k = kind(g);
    v.data()[i] = k == 0 ? 0.0 : k == 1 ? -0.0 : std::ldexp(u(g), e(g));
  }
  return v;
}

// Two participants of n points and the exchange of "f" between them (no mapper). 1539 rows x 3:
// neither a multiple of 2 nor of 4 values (the vector loops' remainders run too).
struct Pair {
  static constexpr Eigen::Index n = 1539;
  std::unique_ptr<LocalParticipant> a = std::make_unique<LocalParticipant>(
      "a", std::make_unique<ArraySolver>(n, DataKind::extensive));
  std::unique_ptr<LocalParticipant> b = std::make_unique<LocalParticipant>(
      "b", std::make_unique<ArraySolver>(n, DataKind::extensive));
  Exchange exchange{"f", {a.get(), "points"}, {b.get(), "points"}, DataSpec{"f", 3, "N"}, nullptr};
};

}  // namespace

TEST_CASE(
    "Participant: the substep average and the time interpolation follow their formulas bit "
    "for bit",
    "[coupling][exchange]") {
  Pair pair;
  Exchange& e = pair.exchange;
  const Eigen::Index n = Pair::n;
  std::mt19937 g(7);
  SECTION("the average of m substeps is the running mean") {
    for (int m = 1; m <= 9; ++m) {
      INFO("substeps " << m);
      LocalParticipant a("a", std::make_unique<ArraySolver>(n, DataKind::extensive),
                         Substeps{false, m});
      auto& solver = static_cast<ArraySolver&>(a.solver());
      Eigen::MatrixXd mean;
      for (int k = 1; k <= m; ++k) {
        const Eigen::MatrixXd v = values(n, g);
        solver.script.push_back(v);
        // f̄_k = f̄_{k-1} + (f_k - f̄_{k-1}) / k, f̄_1 = f_1 (Eigen's own elementwise evaluation)
        if (k == 1)
          mean = v;
        else
          mean = mean + (v - mean) / static_cast<double>(k);
      }
      WindowOutput out = e.window_output();
      a.run_window(TimeWindow(1.0, 0, 1), {}, std::span<WindowOutput>(&out, 1));
      CHECK(same_bits(e.combined(), mean));
    }
    // a constant output averages to itself exactly
    const Eigen::MatrixXd c = values(n, g);
    LocalParticipant a("a", std::make_unique<ArraySolver>(n, DataKind::extensive),
                       Substeps{false, 7});
    static_cast<ArraySolver&>(a.solver()).next = c;
    WindowOutput out = e.window_output();
    a.run_window(TimeWindow(1.0, 0, 1), {}, std::span<WindowOutput>(&out, 1));
    CHECK((e.combined().array() == c.array()).all());
  }
  SECTION("the reader sees d_n + (k/m) (d_n+1 - d_n)") {
    const Eigen::MatrixXd d0 = values(n, g), d1 = values(n, g);
    *e.window_output().combined = d0;
    e.initialize();
    e.sent() = d1;
    e.transmit();
    LocalParticipant b("b", std::make_unique<ArraySolver>(n, DataKind::extensive),
                       Substeps{false, 7});
    auto& solver = static_cast<ArraySolver&>(b.solver());
    solver.log_reads = true;
    const WindowInput in = e.window_input();
    b.run_window(TimeWindow(1.0, 0, 1), std::span<const WindowInput>(&in, 1), {});
    REQUIRE(solver.reads.size() == 7);
    for (int k = 1; k < 7; ++k) {
      const double s = static_cast<double>(k) / 7.0;
      const Eigen::MatrixXd expected = d0 + s * (d1 - d0);
      CHECK(same_bits(solver.reads[static_cast<std::size_t>(k - 1)], expected));
    }
    CHECK(same_bits(solver.reads.back(), d1));
  }
}

TEST_CASE(
    "Exchange mapped on the receiver's side: a second copy of the mapper maps the values that "
    "travel to the receiver's d_n and d_n+1 bit for bit",
    "[coupling][exchange][map_on]") {
  // the sender's mesh (1539 points) is larger than the receiver's (700)
  auto a = std::make_unique<LocalParticipant>(
      "a", std::make_unique<ArraySolver>(1539, DataKind::intensive));
  auto b = std::make_unique<LocalParticipant>(
      "b", std::make_unique<ArraySolver>(700, DataKind::intensive));
  const Mesh& from = a->find_mesh("points")->mesh;
  const Mesh& to = b->find_mesh("points")->mesh;
  auto mapper = std::make_unique<NearestNeighborMapper>(Constraint::consistent);
  mapper->compute(from, to);
  NearestNeighborMapper theirs(Constraint::consistent);  // the receiver's process's own copy
  theirs.compute(from, to);
  Exchange e{"f", {a.get(), "points"}, {b.get(), "points"}, DataSpec{"f", 3, "N"},
             std::move(mapper)};
  CHECK(e.map_on() == MapOn::receiver);  // the default
  e.set_mapped_by_receiver(true);
  std::mt19937 g(11);
  const auto mapped = [&](const Eigen::MatrixXd& sent) {
    Eigen::MatrixXd d;
    theirs.map(sent, d);
    return d;
  };

  *e.window_output().combined = values(1539, g);
  e.initialize();
  WindowInput in = e.window_input();
  REQUIRE(in.sent_end != nullptr);
  CHECK(in.sent_end->rows() == 1539);  // the sender's values travel
  CHECK(in.sent_start == nullptr);     // d_n = d_n+1: only the end is read
  CHECK(same_bits(mapped(*in.sent_end), *in.end));

  for (int window = 0; window < 3; ++window) {  // accepted windows: d_n is the last accepted
    e.accept_window();
    e.sent() = values(1539, g);
    e.transmit();
    in = e.window_input();
    REQUIRE(in.sent_start != nullptr);
    CHECK_FALSE(in.start_is_end);
    CHECK(same_bits(mapped(*in.sent_start), *in.start));
    CHECK(same_bits(mapped(*in.sent_end), *in.end));
    e.sent() = values(1539, g);  // an implicit scheme's next iterate in the same window
    e.transmit();
    in = e.window_input();
    CHECK(same_bits(mapped(*in.sent_start), *in.start));
    CHECK(same_bits(mapped(*in.sent_end), *in.end));
  }

  SECTION("after a restart file d_n travels mapped (its sender's values are not in the file)") {
    std::stringstream file;
    BinaryWriter w(file);
    StateArchive out(w);
    e.serialize(out);
    BinaryReader r(file, "restart");
    StateArchive back(r);
    e.serialize(back);
    in = e.window_input();
    CHECK(in.sent_start == nullptr);
    REQUIRE(in.sent_end != nullptr);
    CHECK(same_bits(mapped(*in.sent_end), *in.end));
  }
}


TEST_CASE("the audit's fused totals follow their formula bit for bit and sum correctly",
          "[coupling][exchange][audit]") {
  std::mt19937 g(11);
  std::uniform_real_distribution<double> u_dist(0.0, 2.0);
  for (const Eigen::Index n : {0, 1, 3, 4, 5, 7, 8, 13, 1539}) {
    for (const bool weighted : {false, true}) {
      INFO("n " << n << (weighted ? ", weighted" : ""));
      Eigen::MatrixXd v = values(n, g);
      for (Eigen::Index i = 0; i < n; i += 3) v.row(i).setZero();  // points without load
      Eigen::VectorXd w(n);
      for (Eigen::Index i = 0; i < n; ++i) w(i) = u_dist(g);
      Eigen::VectorXd u(n);
      for (Eigen::Index i = 0; i < n; ++i) u(i) = u_dist(g);
      const auto t = partita::coupling::elementwise::weighted_totals3(
          v.col(0).data(), v.col(1).data(), v.col(2).data(), weighted ? w.data() : nullptr, n, true,
          u.data());
      const auto plain = partita::coupling::elementwise::weighted_totals3(
          v.col(0).data(), v.col(1).data(), v.col(2).data(), weighted ? w.data() : nullptr, n,
          false);
      const double* total = t.total;
      const double magnitude = t.magnitude;
      // the documented formula: row i into partial sum i mod 4, (s0 + s1) + (s2 + s3)
      double acc[5][4] = {};
      long double exact[5] = {};
      for (Eigen::Index i = 0; i < n; ++i) {
        const double wi = weighted ? w(i) : 1.0;
        for (int c = 0; c < 3; ++c) {
          acc[c][i % 4] += wi * v(i, c);
          exact[c] += static_cast<long double>(wi) * v(i, c);
        }
        const double len = std::sqrt((v(i, 0) * v(i, 0) + v(i, 1) * v(i, 1)) + v(i, 2) * v(i, 2));
        acc[3][i % 4] += std::abs(wi) * len;
        if (len != 0.0) acc[4][i % 4] += u(i) * len;  // (a zero length adds +0 either way)
        exact[3] += static_cast<long double>(std::abs(wi)) * v.row(i).norm();
        exact[4] += static_cast<long double>(u(i)) * v.row(i).norm();
      }
      for (int c = 0; c < 3; ++c) {
        const double expected = (acc[c][0] + acc[c][1]) + (acc[c][2] + acc[c][3]);
        CHECK(std::memcmp(&total[c], &expected, sizeof(double)) == 0);
      }
      const double expected_m = (acc[3][0] + acc[3][1]) + (acc[3][2] + acc[3][3]);
      CHECK(std::memcmp(&magnitude, &expected_m, sizeof(double)) == 0);
      const double expected_b = (acc[4][0] + acc[4][1]) + (acc[4][2] + acc[4][3]);
      CHECK(std::memcmp(&t.bound, &expected_b, sizeof(double)) == 0);
      // without the lengths: the same totals, no lengths summed
      CHECK(std::memcmp(plain.total, t.total, sizeof t.total) == 0);
      CHECK(plain.magnitude == 0.0);
      CHECK(plain.bound == 0.0);
      // and the sums are right: to round-off against a long-double accumulation, relative to
      // the magnitude total (the scale of every term)
      const double scale = static_cast<double>(exact[3]);
      for (int c = 0; c < 3; ++c)
        CHECK(std::abs(total[c] - static_cast<double>(exact[c])) <= 1e-13 * scale);
      CHECK(std::abs(magnitude - scale) <= 1e-13 * scale);
      CHECK(std::abs(t.bound - static_cast<double>(exact[4])) <= 1e-13 * 2.0 * scale + 1e-300);
    }
  }
  // a NaN or an infinity reaches the totals
  Eigen::MatrixXd v = Eigen::MatrixXd::Ones(9, 3);
  v(6, 2) = std::numeric_limits<double>::infinity();
  auto t = partita::coupling::elementwise::weighted_totals3(v.col(0).data(), v.col(1).data(),
                                                            v.col(2).data(), nullptr, 9, true);
  CHECK(std::isinf(t.total[2]));
  CHECK(std::isfinite(t.total[0]));
  v(2, 0) = std::numeric_limits<double>::quiet_NaN();
  t = partita::coupling::elementwise::weighted_totals3(v.col(0).data(), v.col(1).data(),
                                                       v.col(2).data(), nullptr, 9, true);
  CHECK(std::isnan(t.total[0]));
  CHECK(std::isnan(t.magnitude));
}
