// An external program for the test of ExternalParticipant::read() at a relative time
// (tests/mpi/distributed.sh external-read): it reads the field of the plugin solver `ramp`
// (ramp_plugin.cpp: value_i(t) = c_i + r_i t, linear in time) at 0, dt/3, dt/2 and dt of each
// of its steps and compares with the analytic value:
//   reader_sees linear:   c_i + r_i (t + s)   (linear interpolation between the window's ends
//                                              is exact for a field linear in time)
//   reader_sees constant: c_i + r_i t_{n+1}   (the window end's value, whatever s)
// It also asks for a time before and after the step (refused with a UsageError) and checks that
// read() without a time is read at time_step_size() to the bit. Exit 0 when all holds.
// Usage: read_probe CASE linear|constant [--set KEY=VALUE ...]   (under mpirun, beside partita)
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include <Eigen/Core>

#include "partita/mpi/external_participant.hpp"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: read_probe CASE linear|constant [--set KEY=VALUE ...]\n");
    return 2;
  }
  const bool linear = std::string(argv[2]) == "linear";
  partita::mpi::ExternalOptions options;
  for (int i = 3; i + 1 < argc; i += 2) options.overrides.push_back(argv[i + 1]);
  constexpr std::array<double, 3> c = {1.0, -2.0, 0.5}, r = {3.0, -7.0, 0.25};  // ramp_plugin.cpp
  constexpr double window = 0.1;  // external_read.yaml
  try {
    partita::mpi::ExternalParticipant p("probe", argv[1], options);
    partita::Mesh::Points x = partita::Mesh::Points::Zero(3, 3);
    for (int i = 0; i < 3; ++i) x(i, 0) = i;
    p.add_mesh({partita::Mesh("points", x), {{"value", 1, "1", partita::DataKind::intensive}}, {}});
    p.initialize();
    Eigen::MatrixXd v, at_end, without_time;
    double worst = 0.0;
    long reads = 0, steps = 0, refused = 0, bit_equal = 0;
    while (p.is_coupling_ongoing()) {
      const double dt = p.time_step_size(), t = p.time();
      const double window_end = (std::floor((t + 0.5 * dt) / window) + 1.0) * window;
      for (const double s : {0.0, dt / 3.0, 0.5 * dt, dt}) {
        p.read("points", "value", s, v);
        for (int i = 0; i < 3; ++i)
          worst = std::max(worst, std::abs(v(i, 0) - (c[i] + r[i] * (linear ? t + s : window_end))));
        ++reads;
      }
      p.read("points", "value", dt, at_end);
      p.read("points", "value", without_time);
      bit_equal += at_end == without_time;
      for (const double bad : {-1e-3 * dt, dt * (1.0 + 1e-9)}) {
        try {
          p.read("points", "value", bad, v);
        } catch (const partita::mpi::UsageError& e) {
          if (std::string(e.what()).find("must lie in [0, time_step_size()]") != std::string::npos)
            ++refused;
          else
            std::fprintf(stderr, "read_probe: an unclear message: %s\n", e.what());
        }
      }
      ++steps;
      p.advance(dt);
    }
    p.finalize();
    std::printf(
        "read_probe: %ld reads (%s) over %ld steps, at most %.3g from the analytic value; %ld "
        "of %ld times outside the step refused; read() = read(time_step_size()) in %ld of %ld "
        "steps\n",
        reads, linear ? "linear" : "constant", steps, worst, refused, 2 * steps, bit_equal, steps);
    const bool ok = steps == 20 && worst <= 1e-12 && refused == 2 * steps && bit_equal == steps;
    std::printf("read_probe: %s\n", ok ? "passed" : "FAILED");
    return ok ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "read_probe: error: %s\n", e.what());
    return 1;
  }
}
