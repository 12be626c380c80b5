#include "partita/fem/nonlinear_operator.hpp"

#include "block_assembler.hpp"
#include "partita/fem/element_integrator.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/linear_elastic_law.hpp"
#include "partita/fem/quadrature.hpp"

namespace partita::fem {

NonlinearOperator::NonlinearOperator(const Model& model)
    : mesh_(model.mesh()), assembler_(std::make_unique<BlockAssembler>(model.mesh())) {
  const std::size_t regions = std::max<std::size_t>(1, mesh_.region_names().size());
  for (std::size_t r = 0; r < regions; ++r) {
    const auto* law = model.material_law(static_cast<int>(r));
    if (law != nullptr) {
      // shared ownership is not exposed by Model: wrap the pointer without owning it
      region_laws_.emplace_back(std::shared_ptr<const MaterialLaw>(), law);
    } else {
      region_laws_.push_back(
          std::make_shared<LinearElasticLaw>(model.material(static_cast<int>(r))));
    }
  }
  ShapeVector n;
  ShapeGradient g;
  state_offset_.push_back(0);
  for (const auto& e : mesh_.elements()) {
    const MaterialLaw* law = region_laws_.at(static_cast<std::size_t>(e.region)).get();
    element_law_.push_back(law);
    qp_offset_.push_back(weight_.size());
    const ElementCoordinates x = element_coordinates(mesh_, e);
    for (const auto& q : volume_rule(e.type, QuadratureUse::Stiffness)) {
      const double det = physical_gradients(e.type, x, q.xi, n, g);
      weight_.push_back(det * q.weight);
      gradient_offset_.push_back(gradients_.size());
      for (Eigen::Index a = 0; a < g.rows(); ++a) {
        for (int d = 0; d < 3; ++d) gradients_.push_back(g(a, d));
      }
      state_offset_.push_back(state_offset_.back() + static_cast<std::size_t>(law->state_size()));
    }
  }
  qp_offset_.push_back(weight_.size());
  committed_.assign(state_offset_.back(), 0.0);
  for (std::size_t e = 0; e < element_law_.size(); ++e) {
    for (std::size_t q = qp_offset_[e]; q < qp_offset_[e + 1]; ++q) {
      element_law_[e]->initialise_state(
          std::span<double>(committed_)
              .subspan(state_offset_[q], state_offset_[q + 1] - state_offset_[q]));
    }
  }
  trial_ = committed_;
  cauchy_ = MatrixX6::Zero(static_cast<Eigen::Index>(weight_.size()), 6);
  eqps_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(weight_.size()));
}

NonlinearOperator::~NonlinearOperator() = default;

void NonlinearOperator::evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& f_int,
                                 SparseMatrix* k) {
  f_int.setZero(u.size());
  if (k != nullptr) {
    if (k->nonZeros() == 0) *k = assembler_->make_matrix();
    std::fill(k->valuePtr(), k->valuePtr() + k->nonZeros(), 0.0);
  }
  energy_ = 0.0;
  ElementVector fe;
  ElementMatrix ke;
  Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMaxElementNodes, 3> ue;
  Eigen::Matrix<double, 9, 3> ag;  // A_iJkL dN_b/dX_L for one node b: rows iJ, columns k
  MaterialResponse resp;
  const auto& elements = mesh_.elements();
  for (std::size_t e = 0; e < elements.size(); ++e) {
    const Element& el = elements[e];
    const int nn = node_count(el.type);
    const MaterialLaw& law = *element_law_[e];
    ue.resize(nn, 3);
    for (int a = 0; a < nn; ++a) {
      ue.row(a) = u.segment<3>(3 * static_cast<Eigen::Index>(el.nodes[a])).transpose();
    }
    fe.setZero(3 * nn);
    if (k != nullptr) ke.setZero(3 * nn, 3 * nn);
    for (std::size_t q = qp_offset_[e]; q < qp_offset_[e + 1]; ++q) {
      const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> g(
          gradients_.data() + gradient_offset_[q], nn, 3);
      // F = I + sum_a u_a (x) grad_X N_a
      const Mat3 f = Mat3::Identity() + ue.transpose() * g;
      const std::size_t s0 = state_offset_[q], ns = state_offset_[q + 1] - s0;
      law.evaluate(f, std::span<const double>(committed_).subspan(s0, ns),
                   std::span<double>(trial_).subspan(s0, ns), resp);
      const double w = weight_[q];
      energy_ += resp.energy_density * w;
      // f_a,i += P_iJ dN_a/dX_J w
      const Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMaxElementNodes, 3> pg =
          g * (resp.stress.transpose() * w);
      for (int a = 0; a < nn; ++a) fe.segment<3>(3 * a) += pg.row(a).transpose();
      // sigma = P F^T / J (for output)
      const Mat3 sigma = resp.stress * f.transpose() / f.determinant();
      const auto qi = static_cast<Eigen::Index>(q);
      cauchy_.row(qi) << sigma(0, 0), sigma(1, 1), sigma(2, 2), sigma(0, 1), sigma(1, 2),
          sigma(0, 2);
      eqps_[qi] = law.equivalent_plastic_strain(std::span<const double>(trial_).subspan(s0, ns));
      if (k == nullptr) continue;
      // K_(a i)(b k) += dN_a/dX_J A_iJkL dN_b/dX_L w
      for (int b = 0; b < nn; ++b) {
        for (int kk = 0; kk < 3; ++kk) {
          ag.col(kk) = resp.tangent.middleCols<3>(3 * kk) * g.row(b).transpose() * w;
        }
        for (int a = 0; a < nn; ++a) {
          for (int i = 0; i < 3; ++i) {
            ke.block<1, 3>(3 * a + i, 3 * b) += g.row(a) * ag.middleRows<3>(3 * i);
          }
        }
      }
    }
    // f_int = sum_e A_e^T f_e
    for (int a = 0; a < nn; ++a) {
      f_int.segment<3>(3 * static_cast<Eigen::Index>(el.nodes[a])) += fe.segment<3>(3 * a);
    }
    if (k != nullptr) assembler_->add(*k, el.node_span(), ke);
  }
}

double NonlinearOperator::plastic_work() const {
  double wp = 0.0;
  // W_p = sum_q w_p(history_q) det J w
  for (std::size_t e = 0; e < element_law_.size(); ++e) {
    if (element_law_[e]->state_size() == 0) continue;
    for (std::size_t q = qp_offset_[e]; q < qp_offset_[e + 1]; ++q) {
      wp += element_law_[e]->plastic_work_density(
                std::span<const double>(committed_)
                    .subspan(state_offset_[q], state_offset_[q + 1] - state_offset_[q])) *
            weight_[q];
    }
  }
  return wp;
}

void NonlinearOperator::set_committed_state(const std::vector<double>& state) {
  if (state.size() != committed_.size()) {
    throw Error("nonlinear operator: a quadrature-point history of " +
                std::to_string(state.size()) + " values was given, this model has " +
                std::to_string(committed_.size()) + " (state of another model?)");
  }
  committed_ = state;
  trial_ = state;
}

}  // namespace partita::fem
