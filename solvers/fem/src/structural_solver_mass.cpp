// StructuralSolver: the element eigenvalue bound, mass scaling and the explicit stable step.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "partita/fem/error.hpp"
#include "partita/fem/structural_solver.hpp"

#include "partita/fem/element_size.hpp"

namespace partita::fem {

const std::vector<double>& StructuralSolver::element_frequencies_squared() const {
  if (!element_omega2_.empty() || mesh().num_elements() == 0) return element_omega2_;
  // Element eigenvalue bound (Irons 1970; Hughes, The Finite Element Method, 2000, section
  // 9.3): with a lumped mass, omega_max^2 of the mesh <= max_e lambda_max(M_e^-1 K_e), K_e and M_e
  // restricted to the element's free dofs (a constrained dof is zero in every mode). K_e is the
  // element stiffness at rest: the linear-elastic one (Hex8 as the path integrates it) or, for
  // a law, the elasticity tensor of its tangent at F = I.
  const ElementIntegrator full(Hex8Formulation::Full);
  std::vector<Matrix6> d_region;
  for (std::size_t r = 0; r < std::max<std::size_t>(1, mesh().region_names().size()); ++r) {
    const auto* law = model_.material_law(static_cast<int>(r));
    if (law == nullptr) {
      d_region.push_back(model_.material(static_cast<int>(r)).elasticity_matrix());
      continue;
    }
    std::vector<double> state(static_cast<std::size_t>(law->state_size()));
    std::vector<double> trial(state.size());
    law->initialise_state(state);
    MaterialResponse at_rest;
    law->evaluate(Mat3::Identity(), state, trial, at_rest);
    // Voigt D_ab = C_ijkl with a = (i, j), b = (k, l): xx yy zz xy yz zx
    static constexpr int kPair[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}};
    Matrix6 d;
    for (int a = 0; a < 6; ++a) {
      for (int b = 0; b < 6; ++b) {
        d(a, b) = at_rest.tangent(3 * kPair[a][0] + kPair[a][1], 3 * kPair[b][0] + kPair[b][1]);
      }
    }
    d_region.push_back(d);
  }
  std::vector<char> is_free(ndof_, 0);
  for (auto dof : dofs_.free_dofs()) is_free[static_cast<std::size_t>(dof)] = 1;
  element_omega2_.assign(mesh().num_elements(), 0.0);
  ElementMatrix ke;
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxElementNodes, 1> m;
  std::vector<int> free_local;
  for (std::size_t ei = 0; ei < mesh().num_elements(); ++ei) {
    const Element& e = mesh().elements()[ei];
    const ElementCoordinates x = element_coordinates(mesh(), e);
    const auto& d = d_region[static_cast<std::size_t>(e.region)];
    (nonlinear_ != nullptr ? full : integrator_).stiffness(e.type, x, d, ke);
    integrator_.lumped_mass(e.type, x, model_.density(e.region), m);
    free_local.clear();
    for (int a = 0; a < node_count(e.type); ++a) {
      for (int c = 0; c < 3; ++c) {
        if (is_free[3 * e.nodes[a] + static_cast<std::size_t>(c)]) free_local.push_back(3 * a + c);
      }
    }
    if (free_local.empty()) continue;
    // lambda_max of M^-1/2 K M^-1/2 on the free dofs
    const auto nf = static_cast<Eigen::Index>(free_local.size());
    Eigen::MatrixXd a(nf, nf);
    for (Eigen::Index i = 0; i < nf; ++i) {
      for (Eigen::Index j = 0; j < nf; ++j) {
        const int li = free_local[static_cast<std::size_t>(i)];
        const int lj = free_local[static_cast<std::size_t>(j)];
        a(i, j) = ke(li, lj) / std::sqrt(m[li / 3] * m[lj / 3]);
      }
    }
    element_omega2_[ei] = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(a, Eigen::EigenvaluesOnly)
                              .eigenvalues()
                              .maxCoeff();
  }
  return element_omega2_;
}

void StructuralSolver::setup_mass_scaling() {
  const double target = options_.mass_scaling_time_step;
  if (!(target >= 0.0) || !std::isfinite(target))
    throw Error("mass scaling: the target time step must be a finite number >= 0 s (0: off), got " +
                std::to_string(target));
  if (target == 0.0) return;
  if (options_.integrator != Integrator::CentralDifference)
    throw Error(
        "mass scaling is for central-difference analyses (it raises the explicit stable step); "
        "Newmark and static analyses have no stable-step limit: remove the target time step");
  // s_e = (target / dt_e)^2 = target^2 omega_e^2 / 4 where dt_e = 2 / omega_e < target
  const auto& omega2 = element_frequencies_squared();
  mass_scale_.assign(mesh().num_elements(), 1.0);
  element_mass_.assign(mesh().num_elements(), 0.0);
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxElementNodes, 1> m;
  for (std::size_t ei = 0; ei < mesh().num_elements(); ++ei) {
    const Element& e = mesh().elements()[ei];
    mass_scale_[ei] = std::max(1.0, 0.25 * target * target * omega2[ei]);
    integrator_.lumped_mass(e.type, element_coordinates(mesh(), e), model_.density(e.region), m);
    element_mass_[ei] = m.head(node_count(e.type)).sum();
  }
  mass_ready_ = false;
  stable_step_ = -1.0;
}

std::size_t StructuralSolver::mass_scaled_elements() const {
  return static_cast<std::size_t>(
      std::count_if(mass_scale_.begin(), mass_scale_.end(), [](double s) { return s > 1.0; }));
}

double StructuralSolver::physical_mass() const {
  double total = 0.0;
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxElementNodes, 1> m;
  for (std::size_t ei = 0; ei < mesh().num_elements(); ++ei) {
    if (element_eroded(ei)) continue;
    if (!element_mass_.empty()) {
      total += element_mass_[ei];
      continue;
    }
    const Element& e = mesh().elements()[ei];
    integrator_.lumped_mass(e.type, element_coordinates(mesh(), e), model_.density(e.region), m);
    total += m.head(node_count(e.type)).sum();
  }
  return total;
}

double StructuralSolver::added_mass() const {
  double added = 0.0;
  for (std::size_t ei = 0; ei < mass_scale_.size(); ++ei)
    if (!element_eroded(ei)) added += (mass_scale_[ei] - 1.0) * element_mass_[ei];
  return added;
}

double StructuralSolver::stable_time_step() const {
  if (stable_step_ > 0.0) return stable_step_;
  // dt_crit = 2 / omega_max, omega_max^2 <= max_e omega_e^2 / s_e (the scaled masses)
  const auto& omega2_e = element_frequencies_squared();
  double omega2 = 0.0;
  for (std::size_t ei = 0; ei < omega2_e.size(); ++ei)
    omega2 = std::max(omega2, omega2_e[ei] / mass_scale_factor(ei));
  Eigen::VectorXd nodal_mass = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(mesh().num_nodes()));
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxElementNodes, 1> m;
  for (std::size_t ei = 0; ei < mesh().num_elements(); ++ei) {
    const Element& e = mesh().elements()[ei];
    integrator_.lumped_mass(e.type, element_coordinates(mesh(), e), element_density(ei), m);
    for (int a = 0; a < node_count(e.type); ++a) nodal_mass[static_cast<Eigen::Index>(e.nodes[a])] += m[a];
  }
  // contributions (a penalty contact): omega_max^2 <= the elements' + theirs (Weyl's inequality
  // for the sum of the two symmetric M^-1/2 K M^-1/2)
  if (nonlinear_ != nullptr)
    for (std::size_t c = 0; c < nonlinear_->num_contributions(); ++c)
      omega2 += nonlinear_->contribution(c).max_frequency_squared(nodal_mass);
  if (linear_sum_ != nullptr) omega2 += linear_sum_->max_frequency_squared(nodal_mass);
  stable_step_ = omega2 > 0.0 ? 2.0 / std::sqrt(omega2) : std::numeric_limits<double>::infinity();
  if (omega2 > 0.0 && options_.rayleigh_beta > 0.0) {
    // dt <= (2 / omega)(sqrt(1 + xi^2) - xi), xi = beta omega / 2: decreasing in omega, so the
    // bound on omega_max bounds the step
    const double xi = 0.5 * options_.rayleigh_beta * std::sqrt(omega2);
    stable_step_ *= std::sqrt(1.0 + xi * xi) - xi;
  }
  return stable_step_;
}

double StructuralSolver::element_time_step(std::size_t ei) const {
  const auto& omega2 = element_frequencies_squared();
  const std::size_t ne = mesh().num_elements();
  if (element_length0_.size() != ne) {
    element_length0_.resize(ne);
    for (std::size_t k = 0; k < ne; ++k) {
      const Element& e = mesh().elements()[k];
      element_length0_[k] = element_length(e.type, element_coordinates(mesh(), e));
    }
  }
  if (!(omega2[ei] > 0.0) || !(element_length0_[ei] > 0.0))
    return std::numeric_limits<double>::infinity();
  const Element& e = mesh().elements()[ei];
  ElementCoordinates x = element_coordinates(mesh(), e);
  if (kin_.u.size() == static_cast<Eigen::Index>(ndof_))  // (before the first solve: at rest)
    for (int a = 0; a < node_count(e.type); ++a)
      x.row(a) += kin_.u.segment<3>(3 * static_cast<Eigen::Index>(e.nodes[a])).transpose();
  const double at_rest = 2.0 / std::sqrt(omega2[ei] / mass_scale_factor(ei));
  return at_rest * element_length(e.type, x) / element_length0_[ei];
}

double StructuralSolver::min_element_time_step() const {
  double smallest = std::numeric_limits<double>::infinity();
  for (std::size_t ei = 0; ei < mesh().num_elements(); ++ei)
    if (!element_eroded(ei)) smallest = std::min(smallest, element_time_step(ei));
  return smallest;
}

}  // namespace partita::fem
