// An external program that owns its time loop: the wall of the 1D elastic tube (Degroote et al.,
// Comput. Struct. 86 (2008); the preCICE tutorial elastic-tube-1d), the tube law
//   a(p) = a0 ((p0 - 2 rho c^2) / (p - 2 rho c^2))^2,   c^2 = E / (2 rho r0),
// at the N + 1 nodes x_i = i L / N, coupled to partita's tube1d-fluid through
// partita::mpi::ExternalParticipant. Usage (see README.md):
//   mpirun -n 1 partita run tube_external.yaml --participant fluid : -n 1 ./tube_solid tube_external.yaml
// (with the same --set KEY=VALUE options on both sides, if any). Its state in restart files is
// the wall's area; partita run ... --resume DIR on partita's side resumes it.
#include <cmath>
#include <cstring>
#include <iostream>
#include <numbers>
#include <vector>

#include <Eigen/Core>

#include "partita/mpi/external_participant.hpp"

namespace {

// The defaults of partita's tube1d-solid (and of the preCICE tutorial).
struct Wall {
  int cells = 100;
  double length = 10.0, youngs_modulus = 10000.0, density = 1.0;
  double radius = 1.0 / std::sqrt(std::numbers::pi);
  double a0 = 1.0, p0 = 0.0;
  double area_of(double p) const {
    const double two_rho_c2 = 2.0 * density * (youngs_modulus / (2.0 * density * radius));
    const double q = (p0 - two_rho_c2) / (p - two_rho_c2);
    return a0 * q * q;
  }
};

}  // namespace

int main(int argc, char** argv) {
  partita::mpi::ExternalOptions options;  // the --set options of partita's side, the same
  for (int i = 2; i + 1 < argc && std::strcmp(argv[i], "--set") == 0; i += 2)
    options.overrides.push_back(argv[i + 1]);
  if (argc < 2 || argc != 2 + 2 * static_cast<int>(options.overrides.size())) {
    std::cerr << "usage: tube_solid CASE.yaml [--set KEY=VALUE ...] (under mpirun, beside partita, "
                 "with its --set options)\n";
    return 2;
  }
  try {
    const Wall wall;
    partita::mpi::ExternalParticipant solid("solid", argv[1], options);
    // The coupling mesh: the nodes, reading the pressure and writing the area.
    partita::Mesh::Points x = partita::Mesh::Points::Zero(wall.cells + 1, 3);
    for (int i = 0; i <= wall.cells; ++i) x(i, 0) = wall.length / wall.cells * i;
    solid.add_mesh({partita::Mesh("nodes", x),
                    {{"pressure", 1, "Pa", partita::DataKind::intensive}},
                    {{"cross_section_area", 1, "m^2", partita::DataKind::intensive}}});
    Eigen::MatrixXd pressure = Eigen::MatrixXd::Zero(wall.cells + 1, 1);
    Eigen::MatrixXd area(wall.cells + 1, 1), saved_area;
    for (int i = 0; i <= wall.cells; ++i) area(i, 0) = wall.area_of(pressure(i, 0));
    solid.write("nodes", "cross_section_area", area);  // the initial value
    solid.set_monitor("mid_area", "m^2", area(area.rows() / 2, 0));
    // restart files: the area as bytes (written while this thread waits in advance())
    solid.set_restart_writer([&area] {
      std::vector<char> bytes(sizeof(double) * area.size());
      std::memcpy(bytes.data(), area.data(), bytes.size());
      return bytes;
    });
    solid.initialize();
    if (solid.is_resuming()) {
      const std::vector<char>& bytes = solid.restart_state();
      if (bytes.size() != sizeof(double) * area.size()) {
        std::cerr << "tube_solid: the restart point holds " << bytes.size() << " bytes, not the "
                  << sizeof(double) * area.size() << " of this wall's area\n";
        return 1;
      }
      std::memcpy(area.data(), bytes.data(), bytes.size());
      std::cout << "tube_solid: resumed at t = " << solid.time() << " s\n";
    }

    while (solid.is_coupling_ongoing()) {
      if (solid.requires_writing_checkpoint()) saved_area = area;
      const double dt = solid.time_step_size();
      solid.read("nodes", "pressure", pressure);
      for (int i = 0; i <= wall.cells; ++i) area(i, 0) = wall.area_of(pressure(i, 0));
      solid.write("nodes", "cross_section_area", area);
      solid.set_monitor("mid_area", "m^2", area(area.rows() / 2, 0));
      solid.advance(dt);
      if (solid.requires_reading_checkpoint()) area = saved_area;
    }
    solid.finalize();
    if (const int signal = solid.stopped_by_signal()) {  // a restart file was written
      std::cout << "tube_solid: stopped by signal " << signal
                << " (resume with partita run ... --resume DIR)\n";
      return 128 + signal;
    }
    std::cout << "tube_solid: finished\n";
    return 0;
  } catch (const partita::mpi::RunStopped& e) {
    std::cerr << "tube_solid: the run stopped: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "tube_solid: error: " << e.what() << "\n";
    return 1;
  }
}
