#pragma once
#include <string>
#include <vector>

namespace partita::fem {

// What one Newton solve did: residual norms |R_k| (k = 0 is the start), energy norms
// |dx_k . R_k-1| (k >= 1), line-search step lengths, and why it stopped.
struct NewtonReport {
  bool converged = false;
  int iterations = 0;
  double reference_force = 0.0;
  std::vector<double> residual_norms;
  std::vector<double> energy_norms;
  std::vector<double> step_lengths;
  std::string failure;  // empty when converged
};

}  // namespace partita::fem
