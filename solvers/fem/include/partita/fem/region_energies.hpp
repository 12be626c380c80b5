#pragma once
#include <vector>

namespace partita::fem {

// Energies per element region (Mesh::region_names() order) [J]: each the sum over the region's
// elements, so that the regions add up to the model's totals (StructuralSolver::plastic_work(),
// strain_energy() without other operator contributions, kinetic_energy()).
struct RegionEnergies {
  std::vector<double> plastic_work;    // committed int w_p dV (eroded elements: in eroded energy)
  std::vector<double> strain_energy;   // int W dV (linear path: 1/2 u_e^T K_e u_e)
  std::vector<double> kinetic_energy;  // 1/2 v_e^T M_e v_e (lumped or consistent M_e)
};

}  // namespace partita::fem
