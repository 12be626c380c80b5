#pragma once
// The FEM adapter's rupture and energies-by-part keys and monitors:
//   material.failure   {criterion: constant | gl, strain, thickness, uniform_strain,
//                       necking_strain, erosion}: fem::FailureCriterion
//   mesh.box.regions   [{name, from, to}]: element regions of a box mesh (elements whose centre
//                       lies in the box [from, to]; the rest stay in "all")
// Their monitors (declared in fem_monitors.cpp): failed_elements, first_failure_time [s] (-1
// until an element fails), eroded_energy [J], max_equivalent_plastic_strain, and with two or more
// regions <region>.plastic_work | strain_energy | kinetic_energy [J].

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "partita/fem/fem.hpp"
#include "partita/interface/config.hpp"
#include "partita/interface/solver.hpp"

namespace partita::adapters {

std::shared_ptr<config::Spec> fem_failure_spec();
std::shared_ptr<config::Spec> fem_box_region_spec();
// The criterion of material.failure (none when the key is absent).
fem::FailureCriterion build_failure_criterion(const config::Node& material);
// material.failure's rules that the solver would also refuse, at the keys: a law with plastic
// strain (j2-plasticity*), erosion only in central-difference analyses.
void check_failure_keys(const config::Node& material, bool explicit_dynamics);
// mesh.box.regions onto a box mesh (a region that holds no element is an error at its key).
void apply_box_regions(fem::Mesh& mesh, const config::Node& box);

// Logs the first failed element (part, element, centre, time) once, at info level, and the
// count of failed elements at debug level when it grows.
class FailureLog {
 public:
  void after_step(const fem::StructuralSolver& solver, const std::string& participant);
  // after a restore or restart: what the restored state has failed is not news
  void restored(const fem::StructuralSolver& solver);

 private:
  std::size_t count_ = 0;
};

}  // namespace partita::adapters
