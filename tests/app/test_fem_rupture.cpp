// The FE adapter's rupture and energies-by-part keys from YAML
// (tests/inputs/fem/strip_rupture.yaml): the first failure time against the closed form, the
// log line naming the failed element's part, the per-part energies adding up to the totals,
// and erosion keeping the energy balance.
#include <catch2/catch.hpp>

#include "../support/run_command.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using partita::test::quote;

namespace {

struct Run {
  std::string log;
  std::vector<std::vector<double>> probe;  // the last frame of the line probe 
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
};

Run run_strip(const std::vector<std::string>& sets) {
  static int count = 0;
  const fs::path dir = fs::temp_directory_path() / ("partita_rupture_" + std::to_string(::getpid()) +
                                                    "_" + std::to_string(count++));
  std::string cmd = quote(PARTITA_EXECUTABLE) + " run " +
                    quote((fs::path(PARTITA_SOURCE_DIR) / "tests/inputs/fem/strip_rupture.yaml")
                              .string()) +
                    " --output " + quote(dir.string());
  for (const auto& s : sets) cmd += " --set " + quote(s);
  const auto r = partita::test::run_command(cmd);
  INFO(cmd << "\n" << r.output);
  REQUIRE(r.status == 0);
  Run run;
  run.log = r.output;
  std::ifstream in(dir / "rupture.csv");
  std::string line;
  std::getline(in, line);
  std::stringstream h(line);
  for (std::string c; std::getline(h, c, ',');) run.header.push_back(c.substr(0, c.find(" [")));
  while (std::getline(in, line)) {
    std::vector<double> v;
    std::stringstream s(line);
    for (std::string c; std::getline(s, c, ',');) v.push_back(std::stod(c));
    run.rows.push_back(v);
  }
  std::vector<fs::path> frames;
  for (const auto& f : fs::directory_iterator(dir / "probes")) frames.push_back(f.path());
  REQUIRE(!frames.empty());
  std::sort(frames.begin(), frames.end());
  std::ifstream probe(frames.back());
  std::getline(probe, line);
  REQUIRE(line == "s [m],x [m],y [m],z [m],equivalent_plastic_strain");
  while (std::getline(probe, line)) {
    std::vector<double> v;
    std::stringstream s(line);
    for (std::string c; std::getline(s, c, ',');) v.push_back(std::stod(c));
    run.probe.push_back(v);
  }
  fs::remove_all(dir);
  REQUIRE(!run.rows.empty());
  return run;
}

std::size_t column(const Run& r, const std::string& name) {
  for (std::size_t i = 0; i < r.header.size(); ++i)
    if (r.header[i] == name) return i;
  FAIL("no column " << name);
  return 0;
}

}  // namespace

TEST_CASE("fem adapter: a strip's first failure time, its log line and the energies by part",
          "[app][fem][rupture]") {
  const Run r = run_strip({});
  const double t_f = 0.04 * (250e6 + 2e9 * 0.02) / 350e6;
  const auto& last = r.rows.back();
  CHECK(last[column(r, "strip.failed_elements")] == 3.0);
  CHECK(last[column(r, "strip.first_failure_time")] == Approx(t_f).epsilon(0.02));
  CHECK(r.rows.front()[column(r, "strip.first_failure_time")] == -1.0);
  CHECK(r.log.find("first failure at t =") != std::string::npos);
  CHECK(r.log.find("of part '") != std::string::npos);
  // the point's element is the middle one: its mean eps_p, the largest (uniform strip)
  CHECK(last[column(r, "strip.centre.equivalent_plastic_strain")] >= 0.02);
  CHECK(last[column(r, "strip.max_equivalent_plastic_strain")] >=
        last[column(r, "strip.centre.equivalent_plastic_strain")]);
  // the line probe through the three elements' centres: each has failed, eps_p >= eps_f
  REQUIRE(r.probe.size() == 3);
  for (const auto& p : r.probe) CHECK(p[4] >= 0.02);
  // the parts add up to the totals, at every recorded time
  for (const auto& row : r.rows) {
    for (const char* q : {"plastic_work", "kinetic_energy"}) {
      const std::string s(q);
      const double sum = row[column(r, "strip.left." + s)] + row[column(r, "strip.middle." + s)] +
                         row[column(r, "strip.all." + s)];
      CHECK(sum == Approx(row[column(r, "strip." + s)]).epsilon(1e-8).margin(1e-12));  // CSV digits
    }
  }
  // by part: each part's one element fails at t_f (a uniform strip), the parts add up
  for (const char* part : {"left", "middle", "all"}) {
    INFO(part);
    const std::string p = std::string("strip.") + part;
    CHECK(last[column(r, p + ".failed_elements")] == 1.0);
    CHECK(last[column(r, p + ".first_failure_time")] == Approx(t_f).epsilon(0.02));
    CHECK(r.rows.front()[column(r, p + ".first_failure_time")] == -1.0);
  }
  CHECK(std::abs(last[column(r, "strip.energy_balance")]) <
        0.01 * last[column(r, "strip.external_work")]);
}

TEST_CASE("fem adapter: erosion from YAML removes the failed strip, the balance closes",
          "[app][fem][rupture]") {
  const Run r = run_strip({"participants.strip.material.failure.erosion=true"});
  const auto& last = r.rows.back();
  // the first failed element leaves; the rest flies off (and may fail later, or not)
  CHECK(last[column(r, "strip.failed_elements")] >= 1.0);
  CHECK(r.log.find("(eroded)") != std::string::npos);
  CHECK(last[column(r, "strip.eroded_energy")] > 0.0);
  CHECK(last[column(r, "strip.first_failure_time")] ==
        Approx(0.04 * (250e6 + 2e9 * 0.02) / 350e6).epsilon(0.02));
  // by part, at every row: the parts' failed elements add up to the total and the earliest of
  // their first failures is the strip's
  for (const auto& row : r.rows) {
    double count = 0.0, first = -1.0;
    for (const char* part : {"left", "middle", "all"}) {
      const std::string p = std::string("strip.") + part;
      count += row[column(r, p + ".failed_elements")];
      const double t = row[column(r, p + ".first_failure_time")];
      if (t >= 0.0 && (first < 0.0 || t < first)) first = t;
    }
    CHECK(count == row[column(r, "strip.failed_elements")]);
    CHECK(first == row[column(r, "strip.first_failure_time")]);
  }
  CHECK(std::abs(last[column(r, "strip.energy_balance")]) <
        0.01 * last[column(r, "strip.external_work")]);
}

TEST_CASE("fem adapter: rtcl and bwh from YAML fail the strip when uniaxial tension says",
          "[app][fem][rupture]") {
  // uniaxial stress (T = 1/3, alpha = 0): RTCL's damage is eps_p / eps_cr, so eps_cr = 0.02
  // fails the strip when the constant eps_f = 0.02 does; BWH's limit is Hill's K (2n)^n, so
  // K = 290 MPa / 0.4^0.2 with n = 0.2 fails it when sigma reaches 290 MPa, at the same time
  const double t_f = 0.04 * (250e6 + 2e9 * 0.02) / 350e6;
  const std::string k_mpa = std::to_string(290.0 / std::pow(0.4, 0.2));
  for (const std::string failure :
       {std::string("{criterion: rtcl, critical_strain: 0.02}"),
        "{criterion: bwh, strength_coefficient: " + k_mpa + " MPa, hardening_exponent: 0.2}"}) {
    INFO(failure);
    const Run r = run_strip({"participants.strip.material.failure=" + failure});
    const auto& last = r.rows.back();
    CHECK(last[column(r, "strip.failed_elements")] == 3.0);
    CHECK(last[column(r, "strip.first_failure_time")] == Approx(t_f).epsilon(0.02));
    CHECK(r.log.find("mean damage") != std::string::npos);
  }
}

TEST_CASE("fem adapter: the rtcl and bwh keys are refused by name where they do not belong",
          "[app][fem][rupture]") {
  const std::string strip =
      quote((fs::path(PARTITA_SOURCE_DIR) / "tests/inputs/fem/strip_rupture.yaml").string());
  const auto check = [&](const std::string& failure) {
    return partita::test::run_command(quote(PARTITA_EXECUTABLE) + " check " + strip +
                                      " --set " +
                                      quote("participants.strip.material.failure=" + failure));
  };
  struct Bad {
    std::string failure, message;
  };
  for (const Bad& b : {
           Bad{"{criterion: rtcl}", "criterion rtcl needs 'critical_strain'"},
           Bad{"{criterion: rtcl, critical_strain: 0.2, strain: 0.1}",
               "failure.strain': strain belongs to criterion constant, not rtcl"},
           Bad{"{criterion: rtcl, critical_strain: 0.2, uniform_strain: 0.1}",
               "uniform_strain belongs to criterion gl, not rtcl"},
           Bad{"{criterion: rtcl, critical_strain: 0.2, thickness: 0.01, neck_strain: 0.6, "
               "hardening_exponent: 0.2}",
               "critical_strain (eps_cr given) and the size scaling"},
           Bad{"{criterion: rtcl, thickness: 0.01, hardening_exponent: 0.2}", "needs 'neck_strain'"},
           Bad{"{criterion: bwh, hardening_exponent: 0.2}", "needs 'strength_coefficient'"},
           Bad{"{criterion: bwh, strength_coefficient: 530 MPa, hardening_exponent: 1.5}",
               "must be in (0, 1)"},
           Bad{"{criterion: bwh, strength_coefficient: 530 MPa, hardening_exponent: 0.2, "
               "critical_strain: 0.3}",
               "critical_strain belongs to criterion rtcl, not bwh"},
           Bad{"{criterion: gl, thickness: 0.01, strength_coefficient: 530 MPa}",
               "strength_coefficient belongs to criterion bwh, not gl"},
           Bad{"{criterion: constant, strain: 0.1, neck_strain: 0.6}",
               "neck_strain belongs to criterion rtcl or bwh, not constant"},
       }) {
    INFO(b.failure);
    const auto r = check(b.failure);
    INFO(r.output);
    CHECK(r.status != 0);
    CHECK(r.output.find(b.message) != std::string::npos);
  }
  // a size-scaled RTCL and a scaled BWH with their units are valid
  for (const std::string ok :
       {std::string("{criterion: rtcl, thickness: 10 mm, hardening_exponent: 0.2, neck_strain: 0.6}"),
        std::string("{criterion: bwh, strength_coefficient: 530 MPa, hardening_exponent: 0.2, "
                    "thickness: 10 mm, neck_strain: 0.6, erosion: true}")}) {
    INFO(ok);
    const auto r = check(ok);
    INFO(r.output);
    CHECK(r.status == 0);
  }
}
