#include "partita/fem/material_contribution.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <type_traits>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include "parallel_loop.hpp"
#include "partita/fem/element_integrator.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/failure_criterion.hpp"
#include "partita/fem/inverted_element_error.hpp"
#include "partita/fem/linear_elastic_law.hpp"
#include "partita/fem/quadrature.hpp"
#include "partita/fem/shape_functions.hpp"

namespace partita::fem {
namespace {

// ke_(a i)(b k) += scale dN_a/dX_J A_iJkL dN_b/dX_L: the material part of a point's stiffness,
// dF/du^T A dF/du with dF_iJ / du_bk = delta_ik dN_b/dX_J (g: n x 3 gradients); only the
// columns of the nodes b >= first_b (the others are left as they are).
template <typename Gradients, typename Matrix>
void add_material_stiffness(const Gradients& g, const Matrix9& a, double scale, Matrix& ke,
                            Eigen::Index first_b = 0) {
  Eigen::Matrix<double, 9, 3> ag;  // A_iJkL dN_b/dX_L for one node b: rows iJ, columns k
  const auto nn = g.rows();
  for (Eigen::Index b = first_b; b < nn; ++b) {
    for (int kk = 0; kk < 3; ++kk) {
      ag.col(kk) = a.middleCols<3>(3 * kk) * g.row(b).transpose() * scale;
    }
    for (Eigen::Index a_node = 0; a_node < nn; ++a_node) {
      for (int i = 0; i < 3; ++i) {
        ke.template block<1, 3>(3 * a_node + i, 3 * b) += g.row(a_node) * ag.middleRows<3>(3 * i);
      }
    }
  }
}

// The law at one point: with its tangent (implicit paths) or without it (explicit steps).
void evaluate_point(const MaterialLaw& law, const Mat3& f, std::span<const double> committed,
                    std::span<double> trial, bool tangent, MaterialResponse& r) {
  if (tangent) {
    law.evaluate(f, committed, trial, r);
  } else {
    law.evaluate_stress(f, committed, trial, r);
  }
}

// The Cauchy stress of a point for output: a small-strain law returns sigma itself (used as P
// by the operator), a finite-strain law P, whose Cauchy stress is sigma = P F^T / J.
Mat3 cauchy_stress_of(const MaterialLaw& law, const Mat3& p, const Mat3& f) {
  if (law.small_strain()) return p;
  return p * f.transpose() / f.determinant();
}

// The largest entry |A_iJkL| of a law's tangent at rest (lambda + 2 mu for an isotropic law):
// the scale of the stress error that a rounded F causes.
double modulus_at_rest(const MaterialLaw& law) {
  std::vector<double> state(static_cast<std::size_t>(law.state_size())), trial(state.size());
  law.initialise_state(state);
  MaterialResponse r;
  law.evaluate(Mat3::Identity(), state, trial, r);
  return r.tangent.cwiseAbs().maxCoeff();
}

// lambda + 2 mu, lambda and mu of a law's tangent at rest (A_iJkL, index 3 i + J): A_xxxx,
// A_xxyy, A_xyxy (the reduced Hex8's hourglass and enhanced-strain stiffnesses)
Vec3 elastic_constants_at_rest(const MaterialLaw& law) {
  std::vector<double> state(static_cast<std::size_t>(law.state_size())), trial(state.size());
  law.initialise_state(state);
  MaterialResponse r;
  law.evaluate(Mat3::Identity(), state, trial, r);
  return Vec3(r.tangent(0, 0), r.tangent(0, 4), r.tangent(1, 1));
}

// Round-off bound of the stress of a point: eps (|P| + 3 A_max |F|). F = I + grad u is held to
// eps |F| (the identity dominates it at small strain), and the law's P = P(F) turns that into
// an error of about |A| eps |F| per component (3 terms per component, of at most A_max each).
double stress_round_off(const Mat3& p, const Mat3& f, double modulus) {
  return std::numeric_limits<double>::epsilon() * (p.norm() + 3.0 * modulus * f.norm());
}

}  // namespace

MaterialContribution::MaterialContribution(const Model& model)
    : mesh_(model.mesh()),
      fbar_hex8_(model.hex8_formulation() == Hex8Formulation::FBar),
      eas_hex8_(model.hex8_formulation() == Hex8Formulation::IncompatibleModes),
      reduced_hex8_(model.hex8_formulation() == Hex8Formulation::Reduced) {
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
  std::vector<double> region_modulus;
  for (const auto& law : region_laws_) region_modulus.push_back(modulus_at_rest(*law));
  // the reduced Hex8's elastic constants at rest per region: lambda + 2 mu, lambda, mu
  std::vector<Vec3> region_elastic;
  if (reduced_hex8_)
    for (const auto& law : region_laws_) region_elastic.push_back(elastic_constants_at_rest(*law));
  ShapeVector n;
  ShapeGradient g;
  state_offset_.push_back(0);
  for (const auto& e : mesh_.elements()) {
    const MaterialLaw* law = region_laws_.at(static_cast<std::size_t>(e.region)).get();
    element_law_.push_back(law);
    element_modulus_.push_back(region_modulus.at(static_cast<std::size_t>(e.region)));
    qp_offset_.push_back(weight_.size());
    const ElementCoordinates x = element_coordinates(mesh_, e);
    const bool eas = eas_hex8_ && e.type == ElementType::Hex8;
    Mat3 j0_inv = Mat3::Identity();
    double j0 = 0.0;
    const std::vector<VolumeRulePoint>* rule = &volume_rule(e.type, QuadratureUse::Stiffness);
    if (eas) {
      // J0 = dX/dxi at the centre (column J: the element's half-extent along xi_J)
      shape_functions(e.type, Vec3::Zero(), n, g);
      const Mat3 jac0 = x.transpose() * g;
      j0 = jac0.determinant();
      if (!(j0 > 0.0)) {
        throw Error("EAS Hex8: element with det J <= 0 at its centre (inverted or degenerate)");
      }
      j0_inv = jac0.inverse();
      // thin: the thinnest direction less than half as thick as both others
      const Vec3 extent = jac0.colwise().norm();
      int thin = 0;
      extent.minCoeff(&thin);
      bool is_thin = true;
      for (int d = 0; d < 3; ++d)
        if (d != thin && !(2.0 * extent[thin] < extent[d])) is_thin = false;
      if (is_thin) rule = &layered_hex_rule(thin);
    }
    const bool reduced = reduced_hex8_ && e.type == ElementType::Hex8;
    int thickness_axis = 0;
    if (reduced) {
      shape_functions(e.type, Vec3::Zero(), n, g);
      const Mat3 jac0 = x.transpose() * g;
      j0 = jac0.determinant();
      if (!(j0 > 0.0))
        throw Error("reduced Hex8: element with det J <= 0 at its centre (inverted or degenerate)");
      j0_inv = jac0.inverse();
      // the thickness: the thinnest parametric direction; a plate-like element (thinner than
      // 0.9 of both others: 2 points through it would overestimate a plastic hinge's moment by
      // 15 %) gets 6 points through it, others (near-cubes of a solid) 2
      const Vec3 extent = jac0.colwise().norm();
      extent.minCoeff(&thickness_axis);
      bool is_thin = true;
      for (int d = 0; d < 3; ++d)
        if (d != thickness_axis && !(extent[thickness_axis] < 0.9 * extent[d])) is_thin = false;
      rule = &thickness_line_rule(thickness_axis, is_thin ? 6 : 2);
    }
    reduced_start_.push_back(reduced_data_.size());
    eas_gradient_start_.push_back(eas_gradients_.size());
    for (const auto& q : *rule) {
      const double det = physical_gradients(e.type, x, q.xi, n, g);
      weight_.push_back(det * q.weight);
      gradient_offset_.push_back(gradients_.size());
      for (Eigen::Index a = 0; a < g.rows(); ++a) {
        for (int d = 0; d < 3; ++d) gradients_.push_back(g(a, d));
      }
      // |grad N_a| for the round-off bounds (a reference-configuration constant), computed as
      // the element loops did, on the same matrix types
      const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> gm(
          gradients_.data() + gradient_offset_.back(), g.rows(), 3);
      for (Eigen::Index a = 0; a < g.rows(); ++a) gradient_norms_.push_back(gm.row(a).norm());
      if (eas) {
        // g_J = (j0 / j) xi_J (J0^-1)_J
        for (int jj = 0; jj < 3; ++jj) {
          for (int d = 0; d < 3; ++d) eas_gradients_.push_back(j0 / det * q.xi[jj] * j0_inv(jj, d));
        }
        // the EAS loop's norms: its 11 x 3 gradients G, their 8 node rows, the 3 rows g_J
        Eigen::Matrix<double, 11, 3> gx;
        gx.topRows<8>() = gm.topRows<8>();
        gx.bottomRows<3>() = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(
            eas_gradients_.data() + eas_gradients_.size() - 9);
        for (int a = 0; a < 8; ++a) gradient_norms_[gradient_norms_.size() - 8 + a] = gx.row(a).norm();
        eas_norms_.push_back(gx.norm());
        eas_norms_.push_back(gx.bottomRows<3>().norm());
      }
      // reduced Hex8: the enhanced thickness strain's scale at the point, (j0 / j) zeta
      if (reduced_hex8_) reduced_point_scale_.push_back(reduced ? j0 / det * q.xi[thickness_axis] : 0.0);
      state_offset_.push_back(state_offset_.back() + static_cast<std::size_t>(law->state_size()));
    }
    if (reduced)
      setup_reduced_hex8(x, thickness_axis, j0_inv, region_elastic[static_cast<std::size_t>(e.region)]);
  }
  qp_offset_.push_back(weight_.size());
  // the EAS elements' alpha (9 each) after the points' histories
  std::size_t alpha_end = state_offset_.back();
  for (const auto& e : mesh_.elements()) {
    eas_offset_.push_back(alpha_end);
    if (eas_hex8_ && e.type == ElementType::Hex8) alpha_end += 9;
    // its enhanced beta and the h of the last evaluation (enhanced_strain_work)
    if (reduced_hex8_ && e.type == ElementType::Hex8) alpha_end += 2;
  }
  // rupture: each element's failure time (-1: intact), then the eroded energy
  element_failure_strain_.assign(mesh_.num_elements(), std::numeric_limits<double>::infinity());
  element_erodes_.assign(mesh_.num_elements(), 0);
  element_energy_.assign(mesh_.num_elements(), 0.0);
  for (std::size_t e = 0; e < mesh_.num_elements(); ++e) {
    const Element& el = mesh_.elements()[e];
    const FailureCriterion& c = model.failure_criterion(el.region);
    if (!c.active()) continue;
    if (element_law_[e]->state_size() == 0) {
      throw Error("region '" + mesh_.region_names().at(static_cast<std::size_t>(el.region)) +
                  "': a failure criterion needs a law with plastic strain (j2-plasticity); '" +
                  std::string(element_law_[e]->name()) + "' has none and would never fail");
    }
    element_failure_strain_[e] = c.failure_strain(failure_element_length(mesh_, el));
    element_erodes_[e] = c.erosion ? 1 : 0;
    erosion_ = erosion_ || c.erosion;
    failure_offset_ = alpha_end;
  }
  if (failure_offset_ != kNoFailure) alpha_end += mesh_.num_elements() + 1;
  if (reduced_hex8_) {
    enhanced_work_offset_ = alpha_end++;
    enhanced_work_trial_.assign(mesh_.num_elements(), 0.0);
  }
  committed_.assign(alpha_end, 0.0);
  if (failure_offset_ != kNoFailure) {
    std::fill_n(committed_.begin() + static_cast<std::ptrdiff_t>(failure_offset_),
                mesh_.num_elements(), -1.0);
  }
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

MaterialContribution::~MaterialContribution() = default;

void MaterialContribution::add(const Eigen::VectorXd& u, Eigen::VectorXd& f_int, SparseMatrix* k,
                               const BlockAssembler& assembler) {
  energy_ = 0.0;
  if (k == nullptr) {
    add_force_only(u, f_int);
    return;
  }
  // Elements are evaluated a chunk at a time, the chunk's elements in parallel (each writes only
  // its own quadrature points and its own slot of the chunk buffers), then added to f_int and K
  // serially in element order: the sums are the same, bit for bit, on any number of threads.
  constexpr std::size_t kChunk = 1024;
  const auto& elements = mesh_.elements();
  const std::size_t ne = elements.size();
  if (chunk_fe_.size() < std::min(ne, kChunk)) {
    chunk_fe_.resize(std::min(ne, kChunk));
    chunk_ke_.resize(std::min(ne, kChunk));
    chunk_energy_.resize(std::min(ne, kChunk));
    chunk_fabs_.resize(std::min(ne, kChunk));
  }
  node_round_off_.setZero(static_cast<Eigen::Index>(mesh_.num_nodes()));
  using Clock = std::chrono::steady_clock;
  phase_seconds_ = {};
  for (std::size_t c0 = 0; c0 < ne; c0 += kChunk) {
    const long n = static_cast<long>(std::min(ne - c0, kChunk));
    // A material law may throw (a radial return that does not converge: the Newton solver cuts
    // the step back): the first element's exception comes out, as from a serial loop.
    const auto t0 = Clock::now();
    detail::parallel_for_first_error(n, 32, [&](long i) {
      const auto slot = static_cast<std::size_t>(i);
      evaluate_element(c0 + slot, u, chunk_fe_[slot], &chunk_ke_[slot], chunk_fabs_[slot],
                       chunk_energy_[slot]);
    });
    const auto t1 = Clock::now();
    phase_seconds_.elements += std::chrono::duration<double>(t1 - t0).count();
    for (long i = 0; i < n; ++i) {
      const Element& el = elements[c0 + static_cast<std::size_t>(i)];
      const int nn = node_count(el.type);
      const ElementVector& fe = chunk_fe_[static_cast<std::size_t>(i)];
      // f_int = sum_e A_e^T f_e
      for (int a = 0; a < nn; ++a) {
        f_int.segment<3>(3 * static_cast<Eigen::Index>(el.nodes[a])) += fe.segment<3>(3 * a);
      }
      assembler.add(*k, el.node_span(), chunk_ke_[static_cast<std::size_t>(i)]);
      energy_ += chunk_energy_[static_cast<std::size_t>(i)];
      element_energy_[c0 + static_cast<std::size_t>(i)] = chunk_energy_[static_cast<std::size_t>(i)];
      const ElementVector& fa = chunk_fabs_[static_cast<std::size_t>(i)];
      for (int a = 0; a < nn; ++a) node_round_off_[static_cast<Eigen::Index>(el.nodes[a])] += fa[a];
    }
    phase_seconds_.assembly += std::chrono::duration<double>(Clock::now() - t1).count();
  }
  // r_eps = |a|, a_(n i) = sum_e sum_q |grad N_n| dP_q w_q for each of the 3 components of node n
  round_off_ = std::sqrt(3.0) * node_round_off_.norm();
}

void MaterialContribution::require_not_inverted(std::size_t e, double det_f) const {
  if (det_f > 0.0) return;
  const Element& el = mesh_.elements()[e];
  Vec3 centre = Vec3::Zero();
  const int nn = node_count(el.type);
  for (int a = 0; a < nn; ++a) centre += mesh_.node(el.nodes[a]);
  centre /= nn;
  std::ostringstream msg;
  msg << "element " << e << " (centre at (" << centre.x() << ", " << centre.y() << ", "
      << centre.z() << ") m) is turned inside out: det F = " << det_f
      << " <= 0 at one of its points";
  throw InvertedElementError(msg.str());
}

// ---- explicit steps: the force alone (timed by bench/fem/bench_fem_explicit) ----
// All elements in one parallel loop, each into its own slice of flat buffers (no allocation:
// the element vectors live on the stack), then the nodes in parallel, each node's sum over its
// elements in element order: f_int, the round-off bounds and the energy have the bits of the
// chunked loop of add() on any number of threads (every entry's additions in the same order),
// without its serial assembly and a parallel region per chunk.
void MaterialContribution::add_force_only(const Eigen::VectorXd& u, Eigen::VectorXd& f_int) {
  using Clock = std::chrono::steady_clock;
  const auto& elements = mesh_.elements();
  const std::size_t ne = elements.size(), nodes = mesh_.num_nodes();
  if (flat_offset_.size() != ne + 1) {
    // element e's nodal values at flat_offset_[e] + a; per node, its (e, a) in element order
    flat_offset_.assign(1, 0);
    std::vector<std::size_t> count(nodes + 1, 0);
    for (const auto& el : elements) {
      const int nn = node_count(el.type);
      flat_offset_.push_back(flat_offset_.back() + static_cast<std::size_t>(nn));
      for (int a = 0; a < nn; ++a) ++count[el.nodes[a] + 1];
    }
    for (std::size_t n = 0; n < nodes; ++n) count[n + 1] += count[n];
    node_incidence_offset_ = count;
    node_incidence_.assign(flat_offset_.back(), 0);
    for (std::size_t e = 0; e < ne; ++e) {
      const int nn = node_count(elements[e].type);
      for (int a = 0; a < nn; ++a)
        node_incidence_[count[elements[e].nodes[a]]++] = flat_offset_[e] + static_cast<std::size_t>(a);
    }
    flat_fe_.assign(3 * flat_offset_.back(), 0.0);
    flat_fabs_.assign(flat_offset_.back(), 0.0);
    element_energy_.assign(ne, 0.0);  // (sized by the constructor already; kept for clarity)
  }
  const auto t0 = Clock::now();
  // A material law may throw: the first element's exception comes out, as from a serial loop.
  detail::parallel_for_first_error(static_cast<long>(ne), 32, [&](long i) {
    const auto e = static_cast<std::size_t>(i);
    ElementVector fe, fabs;
    evaluate_element(e, u, fe, nullptr, fabs, element_energy_[e]);
    const std::size_t at = flat_offset_[e];
    std::copy(fe.data(), fe.data() + fe.size(), flat_fe_.data() + 3 * at);
    std::copy(fabs.data(), fabs.data() + fabs.size(), flat_fabs_.data() + at);
  });
  const auto t1 = Clock::now();
  node_round_off_.setZero(static_cast<Eigen::Index>(nodes));
  constexpr long kNodeBlock = 1024;
  const long blocks = static_cast<long>((nodes + kNodeBlock - 1) / kNodeBlock);
  detail::parallel_for_first_error(blocks, 2, [&](long b) {
    const std::size_t n0 = static_cast<std::size_t>(b * kNodeBlock);
    const std::size_t n1 = std::min(nodes, n0 + static_cast<std::size_t>(kNodeBlock));
    for (std::size_t n = n0; n < n1; ++n) {
      for (std::size_t j = node_incidence_offset_[n]; j < node_incidence_offset_[n + 1]; ++j) {
        const std::size_t k = node_incidence_[j];
        for (int c = 0; c < 3; ++c) f_int[static_cast<Eigen::Index>(3 * n) + c] += flat_fe_[3 * k + static_cast<std::size_t>(c)];
        node_round_off_[static_cast<Eigen::Index>(n)] += flat_fabs_[k];
      }
    }
  });
  for (std::size_t e = 0; e < ne; ++e) energy_ += element_energy_[e];
  round_off_ = std::sqrt(3.0) * node_round_off_.norm();
  phase_seconds_.elements = std::chrono::duration<double>(t1 - t0).count();
  phase_seconds_.assembly = std::chrono::duration<double>(Clock::now() - t1).count();
}
// ---- end explicit ----

void MaterialContribution::evaluate_element(std::size_t e, const Eigen::VectorXd& u,
                                            ElementVector& fe, ElementMatrix* ke,
                                            ElementVector& fabs, double& energy) {
  const Element& el = mesh_.elements()[e];
  const int nn = node_count(el.type);
  ElementDisplacements ue(nn, 3);
  for (int a = 0; a < nn; ++a) {
    ue.row(a) = u.segment<3>(3 * static_cast<Eigen::Index>(el.nodes[a])).transpose();
  }
  energy = 0.0;
  fe.setZero(3 * nn);
  fabs.setZero(nn);
  if (ke != nullptr) ke->setZero(3 * nn, 3 * nn);
  if (!enhanced_work_trial_.empty()) enhanced_work_trial_[e] = 0.0;
  if (failure_offset_ != kNoFailure && eroded(e)) return;  // an eroded element: nothing
  if (eas_hex8_ && el.type == ElementType::Hex8) {
    evaluate_eas(e, ue, fe, ke, energy, fabs);
  } else if (reduced_hex8_ && el.type == ElementType::Hex8) {
    evaluate_reduced(e, ue, fe, ke, energy, fabs);
  } else if (fbar_hex8_ && el.type == ElementType::Hex8) {
    evaluate_fbar(e, ue, fe, ke, energy, fabs);
  } else {
    evaluate_plain(e, ue, fe, ke, energy, fabs);
  }
}

void MaterialContribution::evaluate_plain(std::size_t e, const ElementDisplacements& ue,
                                          ElementVector& fe, ElementMatrix* ke, double& energy,
                                          ElementVector& fabs) {
  const Element& el = mesh_.elements()[e];
  const int nn = node_count(el.type);
  const MaterialLaw& law = *element_law_[e];
  MaterialResponse resp;
  // N: the node count as a compile-time size (Hex8: fixed-size products, for the explicit
  // benchmark's speed) or Eigen::Dynamic (the other elements)
  auto points = [&]<int N>(std::integral_constant<int, N>) {
    constexpr int kMax = N == Eigen::Dynamic ? kMaxElementNodes : N;
    using Gradients = Eigen::Matrix<double, N, 3, Eigen::RowMajor, kMax, 3>;
    const Eigen::Matrix<double, N, 3, 0, kMax, 3> un = ue.topRows(nn);
    for (std::size_t q = qp_offset_[e]; q < qp_offset_[e + 1]; ++q) {
      const Eigen::Map<const Gradients> g(gradients_.data() + gradient_offset_[q], nn, 3);
      // F = I + sum_a u_a (x) grad_X N_a
      const Mat3 f = Mat3::Identity() + un.transpose() * g;
      if (!law.small_strain()) require_not_inverted(e, f.determinant());
      const std::size_t s0 = state_offset_[q], ns = state_offset_[q + 1] - s0;
      evaluate_point(law, f, std::span<const double>(committed_).subspan(s0, ns),
                     std::span<double>(trial_).subspan(s0, ns), ke != nullptr, resp);
      const double w = weight_[q];
      energy += resp.energy_density * w;
      // f_a,i += P_iJ dN_a/dX_J w
      const Eigen::Matrix<double, N, 3, 0, kMax, 3> pg = g * (resp.stress.transpose() * w);
      for (int a = 0; a < nn; ++a) fe.segment<3>(3 * a) += pg.row(a).transpose();
      // round-off bound of those: |grad N_a| dP w
      const double dp = stress_round_off(resp.stress, f, element_modulus_[e]) * w;
      const double* gn = gradient_norms_.data() + gradient_offset_[q] / 3;
      for (int a = 0; a < nn; ++a) fabs[a] += gn[a] * dp;
      // sigma = P F^T / J for output (small-strain laws: sigma itself)
      const Mat3 sigma = cauchy_stress_of(law, resp.stress, f);
      const auto qi = static_cast<Eigen::Index>(q);
      cauchy_.row(qi) << sigma(0, 0), sigma(1, 1), sigma(2, 2), sigma(0, 1), sigma(1, 2),
          sigma(0, 2);
      eqps_[qi] = law.equivalent_plastic_strain(std::span<const double>(trial_).subspan(s0, ns));
      // K_(a i)(b k) += dN_a/dX_J A_iJkL dN_b/dX_L w
      if (ke != nullptr) add_material_stiffness(g, resp.tangent, w, *ke);
    }
  };
  if (nn == 8) {
    points(std::integral_constant<int, 8>{});
  } else {
    points(std::integral_constant<int, Eigen::Dynamic>{});
  }
}

void MaterialContribution::evaluate_fbar(std::size_t e, const ElementDisplacements& ue,
                                         ElementVector& fe, ElementMatrix* ke, double& energy,
                                         ElementVector& fabs) {
  using Vec24 = Eigen::Matrix<double, 24, 1>;
  using Mat24 = Eigen::Matrix<double, 24, 24>;
  constexpr int kPoints = 8;
  const MaterialLaw& law = *element_law_[e];
  const std::size_t q0 = qp_offset_[e];
  auto gradient = [&](int q) {
    return Eigen::Map<const Eigen::Matrix<double, 8, 3, Eigen::RowMajor>>(
        gradients_.data() + gradient_offset_[q0 + static_cast<std::size_t>(q)]);
  };
  // H = d^2 ln J / du du:  H_(a i)(b k) = -d_ak d_bi  with d_ai = (F^-T grad_X N_a)_i
  auto hessian_ln_j = [](const Vec24& d, Mat24& h) {
    for (int a = 0; a < 8; ++a)
      for (int b = 0; b < 8; ++b)
        h.block<3, 3>(3 * a, 3 * b) = -d.segment<3>(3 * b) * d.segment<3>(3 * a).transpose();
  };
  // Pass 1: F, J and d ln J / du at each point; J_bar = int J dV / V and its derivatives.
  std::array<Mat3, kPoints> f;
  std::array<double, kPoints> j;
  std::array<Vec24, kPoints> d;
  double volume = 0.0, jv = 0.0;
  Vec24 d_bar = Vec24::Zero();
  for (int q = 0; q < kPoints; ++q) {
    const auto g = gradient(q);
    f[q] = Mat3::Identity() + ue.transpose() * g;
    j[q] = f[q].determinant();
    require_not_inverted(e, j[q]);
    const Eigen::Matrix<double, 8, 3> dq = g * f[q].inverse();  // row a: (F^-T grad N_a)^T
    for (int a = 0; a < 8; ++a) d[q].segment<3>(3 * a) = dq.row(a).transpose();
    const double w = weight_[q0 + static_cast<std::size_t>(q)];
    volume += w;
    jv += w * j[q];
    d_bar += (w * j[q]) * d[q];
  }
  const double j_bar = jv / volume;
  d_bar /= jv;  // d ln J_bar = int J d dV / int J dV
  Mat24 h_bar, h;
  if (ke != nullptr) {
    // d^2 ln J_bar = int J (d d^T + H) dV / int J dV - d_bar d_bar^T
    h_bar = -d_bar * d_bar.transpose();
    for (int q = 0; q < kPoints; ++q) {
      hessian_ln_j(d[q], h);
      h_bar +=
          (weight_[q0 + static_cast<std::size_t>(q)] * j[q] / jv) * (h + d[q] * d[q].transpose());
    }
  }
  // Pass 2: the law at F_bar. With dF_bar/du = B_bar = s (G + f e^T) (G = dF/du, f = vec F,
  // e = (d_bar - d) / 3) and p = vec P_bar:
  //   f_e += w s (G^T p + (F : P_bar) e)
  //   K_e += w [s^2 (G^T A G + (G^T A f) e^T + e (G^T A^T f)^T + (f . A f) e e^T)
  //             + s (e c^T + c e^T + (F : P_bar)(e e^T + (H_bar - H) / 3))],  c = G^T p,
  // the rank-one terms written out so that a point costs about twice a plain one.
  MaterialResponse resp;
  Eigen::Matrix<double, 9, 1> fv, af, atf;
  Vec24 c, ga, gat;
  double h_bar_scale = 0.0;  // sum over the points of w s (F : P_bar) / 3
  for (int q = 0; q < kPoints; ++q) {
    const std::size_t qp = q0 + static_cast<std::size_t>(q);
    const auto g = gradient(q);
    const double s = std::cbrt(j_bar / j[q]);
    const Mat3 fb = s * f[q];
    const std::size_t s0 = state_offset_[qp], ns = state_offset_[qp + 1] - s0;
    evaluate_point(law, fb, std::span<const double>(committed_).subspan(s0, ns),
                   std::span<double>(trial_).subspan(s0, ns), ke != nullptr, resp);
    const double w = weight_[qp];
    energy += resp.energy_density * w;
    const Mat3 sigma = cauchy_stress_of(law, resp.stress, fb);
    const auto qi = static_cast<Eigen::Index>(qp);
    cauchy_.row(qi) << sigma(0, 0), sigma(1, 1), sigma(2, 2), sigma(0, 1), sigma(1, 2), sigma(0, 2);
    eqps_[qi] = law.equivalent_plastic_strain(std::span<const double>(trial_).subspan(s0, ns));
    // c_bk = (P_bar grad N_b)_k = (G^T p)_bk;  phi = F : P_bar
    for (int b = 0; b < 8; ++b) c.segment<3>(3 * b) = resp.stress * g.row(b).transpose();
    const double phi = (f[q].array() * resp.stress.array()).sum();
    const Vec24 ev = (d_bar - d[q]) / 3.0;
    fe.head<24>() += (w * s) * (c + phi * ev);
    // round-off bound (as the plain element's, with F_bar)
    const double dp = stress_round_off(resp.stress, fb, element_modulus_[e]) * w * s;
    for (int a = 0; a < 8; ++a) fabs[a] += g.row(a).norm() * dp;
    if (ke == nullptr) continue;
    for (int i = 0; i < 3; ++i)
      for (int jj = 0; jj < 3; ++jj) fv[3 * i + jj] = f[q](i, jj);
    af = resp.tangent * fv;
    atf = resp.tangent.transpose() * fv;
    // (G^T v)_bk = sum_J v_kJ dN_b/dX_J for a 9-vector v indexed 3 k + J
    for (int b = 0; b < 8; ++b) {
      for (int kk = 0; kk < 3; ++kk) {
        ga[3 * b + kk] = g.row(b).dot(af.segment<3>(3 * kk));
        gat[3 * b + kk] = g.row(b).dot(atf.segment<3>(3 * kk));
      }
    }
    add_material_stiffness(g, resp.tangent, w * s * s, *ke);
    const Vec24 left = (s * s) * ga + s * c, right = (s * s) * gat + s * c;
    auto k24 = ke->topLeftCorner<24, 24>();
    k24.noalias() += w * (left * ev.transpose() + ev * right.transpose());
    k24.noalias() += (w * (s * s * fv.dot(af) + s * phi)) * (ev * ev.transpose());
    // - (w s phi / 3) H at this point; + (w s phi / 3) H_bar collected below
    const double hs = w * s * phi / 3.0;
    for (int a = 0; a < 8; ++a)
      for (int b = 0; b < 8; ++b)
        k24.block<3, 3>(3 * a, 3 * b).noalias() +=
            hs * d[q].segment<3>(3 * b) * d[q].segment<3>(3 * a).transpose();
    h_bar_scale += hs;
  }
  if (ke != nullptr) ke->topLeftCorner<24, 24>() += h_bar_scale * h_bar;
}

void MaterialContribution::evaluate_eas(std::size_t e, const ElementDisplacements& ue,
                                        ElementVector& fe, ElementMatrix* ke, double& energy,
                                        ElementVector& fabs) {
  using Vec9 = Eigen::Matrix<double, 9, 1>;
  using Mat9 = Eigen::Matrix<double, 9, 9>;
  using Mat33 = Eigen::Matrix<double, 33, 33>;
  using Vec33 = Eigen::Matrix<double, 33, 1>;
  using Grad11 = Eigen::Matrix<double, 11, 3>;
  constexpr int kMaxLocalIterations = 12;
  const MaterialLaw& law = *element_law_[e];
  const std::size_t q0 = qp_offset_[e], q1 = qp_offset_[e + 1];
  const std::size_t a0 = eas_offset_[e];
  // 11 "nodes": the 8 nodes, then the three enhanced modes (displacements alpha_J)
  Eigen::Matrix<double, 11, 3> ux;
  ux.topRows<8>() = ue.topRows(8);
  Vec9 alpha = Eigen::Map<const Vec9>(committed_.data() + a0);
  Grad11 gx;
  Vec33 fx;
  Mat33 kx;
  MaterialResponse resp;
  // One pass over the points at alpha: fx = int G^T P dV, kx = int G^T A G dV (11 nodes), the
  // energy, the stresses, the trial histories, the round-off bounds; sets the stress scale
  // sum |P| |G| w of h and the round-off bound of h, sum dP |g_J| w (as the nodes' fabs).
  double scale = 0.0, h_round_off = 0.0;
  // ---- explicit steps (no element tangent wanted; bench/fem/bench_fem_explicit) ----
  // Only K_aa of kx is assembled (the 3 enhanced "nodes", the same entries, the same bits: the
  // local Newton is unchanged) and each point's tangent A is kept; the condensation's
  // K_ua d_alpha = sum_q w G_u^T A_q (G_a d_alpha) is then one product per point (below)
  // instead of K_ua assembled in every pass (its sums in another order: round-off of a
  // correction that is itself ~1e-10 of f). A point's tangent: 648 bytes on the stack.
  constexpr std::size_t kMaxExplicitPoints = 24;  // 2 x 2 x 6, the thin elements' rule
  const bool explicit_step = ke == nullptr && q1 - q0 <= kMaxExplicitPoints;
  std::array<Matrix9, kMaxExplicitPoints> point_tangent;
  Mat9 kaa;
  // ---- end explicit ----
  auto pass = [&]() {
    for (int jj = 0; jj < 3; ++jj) ux.row(8 + jj) = alpha.segment<3>(3 * jj).transpose();
    fx.setZero();
    if (explicit_step) {
      kaa.setZero();
    } else {
      kx.setZero();
    }
    fabs.setZero(8);
    energy = 0.0;
    scale = 0.0;
    h_round_off = 0.0;
    for (std::size_t q = q0; q < q1; ++q) {
      gx.topRows<8>() = Eigen::Map<const Eigen::Matrix<double, 8, 3, Eigen::RowMajor>>(
          gradients_.data() + gradient_offset_[q]);
      gx.bottomRows<3>() = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(
          eas_gradients_.data() + eas_gradient_start_[e] + 9 * (q - q0));
      // F = I + sum_a u_a (x) grad_X N_a + sum_J alpha_J (x) g_J
      const Mat3 f = Mat3::Identity() + ux.transpose() * gx;
      if (!law.small_strain()) require_not_inverted(e, f.determinant());
      const std::size_t s0 = state_offset_[q], ns = state_offset_[q + 1] - s0;
      law.evaluate(f, std::span<const double>(committed_).subspan(s0, ns),
                   std::span<double>(trial_).subspan(s0, ns), resp);
      const double w = weight_[q];
      // f_(a i) += P_iJ dG_a/dX_J w   (a over the 11 nodes)
      const Grad11 pg = gx * (resp.stress.transpose() * w);
      for (int a = 0; a < 11; ++a) fx.segment<3>(3 * a) += pg.row(a).transpose();
      // K_(a i)(b k) += dG_a/dX_J A_iJkL dG_b/dX_L w
      if (explicit_step) {
        add_material_stiffness(gx.bottomRows<3>(), resp.tangent, w, kaa);
        point_tangent[q - q0] = resp.tangent;
      } else {
        add_material_stiffness(gx, resp.tangent, w, kx);
      }
      const double* gn = gradient_norms_.data() + gradient_offset_[q] / 3;
      const double* en = eas_norms_.data() + (eas_gradient_start_[e] / 9 + (q - q0)) * 2;
      scale += resp.stress.norm() * en[0] * w;
      energy += resp.energy_density * w;
      const double dp = stress_round_off(resp.stress, f, element_modulus_[e]) * w;
      for (int a = 0; a < 8; ++a) fabs[a] += gn[a] * dp;
      h_round_off += en[1] * dp;
      const Mat3 sigma = cauchy_stress_of(law, resp.stress, f);
      const auto qi = static_cast<Eigen::Index>(q);
      cauchy_.row(qi) << sigma(0, 0), sigma(1, 1), sigma(2, 2), sigma(0, 1), sigma(1, 2),
          sigma(0, 2);
      eqps_[qi] = law.equivalent_plastic_strain(std::span<const double>(trial_).subspan(s0, ns));
    }
  };
  // local Newton on h(alpha) = int G_alpha^T P dV = 0:  K_aa d_alpha = -h, from the committed
  // alpha; each pass writes the energy, stresses and trial histories of its alpha, so the last
  // one's stay
  Eigen::PartialPivLU<Mat9> lu;
  Vec9 h;
  bool converged = false;
  // converged: |h| <= 1e-10 of its scale, or at its round-off (F = I + grad u is rounded to
  // eps |F|: at strains of 1e-8 that is 1e-8 of h's scale), or no longer decreasing within
  // 1e-6 of its scale (round-off the bound does not cover)
  double h_previous = 0.0;
  for (int it = 0; it < kMaxLocalIterations && !converged; ++it) {
    if (it > 0) alpha -= lu.solve(h);
    pass();
    h = fx.tail<9>();
    if (explicit_step) {
      lu.compute(kaa);
    } else {
      lu.compute(kx.bottomRightCorner<9, 9>());
    }
    const double hn = h.norm();
    converged = hn <= 1e-10 * scale + h_round_off || scale == 0.0 ||
                (it > 0 && hn > 0.5 * h_previous && hn <= 1e-6 * scale);
    h_previous = hn;
  }
  if (!converged) {
    std::ostringstream msg;
    msg << "EAS Hex8 element " << e << ": the enhanced strains did not converge in "
        << kMaxLocalIterations << " local iterations";
    throw Error(msg.str());
  }
  // f_e = f_u - K_ua K_aa^-1 h   (h ~ 0: the first-order correction of what is left); the trial
  // alpha likewise alpha - K_aa^-1 h
  const Vec9 d_alpha = lu.solve(h);
  Eigen::Map<Vec9>(trial_.data() + a0) = alpha - d_alpha;
  if (explicit_step) {
    // K_ua d_alpha = sum_q w G_u^T dP_q,  dP = A_q : dF_q,  dF = sum_J d_alpha_J (x) g_J
    fe.head<24>() = fx.head<24>();
    Eigen::Matrix<double, 3, 3> d_rows;  // row J: d_alpha_J
    for (int jj = 0; jj < 3; ++jj) d_rows.row(jj) = d_alpha.segment<3>(3 * jj).transpose();
    for (std::size_t q = q0; q < q1; ++q) {
      const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> ga(
          eas_gradients_.data() + eas_gradient_start_[e] + 9 * (q - q0));
      const Mat3 df = d_rows.transpose() * ga;
      Eigen::Matrix<double, 9, 1> dfv;  // 3 k + L
      for (int kk = 0; kk < 3; ++kk)
        for (int ll = 0; ll < 3; ++ll) dfv[3 * kk + ll] = df(kk, ll);
      const Eigen::Matrix<double, 9, 1> dpv = point_tangent[q - q0] * dfv;  // 3 i + J
      Mat3 dp;
      for (int i = 0; i < 3; ++i)
        for (int jj = 0; jj < 3; ++jj) dp(i, jj) = dpv[3 * i + jj] * weight_[q];
      const Eigen::Map<const Eigen::Matrix<double, 8, 3, Eigen::RowMajor>> gu(
          gradients_.data() + gradient_offset_[q]);
      const Eigen::Matrix<double, 8, 3> pg = gu * dp.transpose();
      for (int a = 0; a < 8; ++a) fe.segment<3>(3 * a) -= pg.row(a).transpose();
    }
    return;
  }
  fe.head<24>() = fx.head<24>() - kx.topRightCorner<24, 9>() * d_alpha;
  if (ke == nullptr) return;
  // K_e = K_uu - K_ua K_aa^-1 K_au
  const Eigen::Matrix<double, 9, 24> kaa_kau = lu.solve(kx.bottomLeftCorner<9, 24>());
  ke->topLeftCorner<24, 24>() = kx.topLeftCorner<24, 24>() - kx.topRightCorner<24, 9>() * kaa_kau;
}

void MaterialContribution::commit() {
  if (enhanced_work_offset_ != kNoFailure) {
    double w = committed_[enhanced_work_offset_];
    for (double we : enhanced_work_trial_) w += we;
    trial_[enhanced_work_offset_] = w;
  }
  // Explicit steps commit every step, ~1 kB of history per element: the copy shared by the
  // threads (bench/fem/bench_fem_explicit; a plain copy, the same bits).
  constexpr std::size_t kBlock = 1 << 15;
  const std::size_t n = trial_.size();
  committed_.resize(n);
  const auto blocks = static_cast<long>((n + kBlock - 1) / kBlock);
  detail::parallel_for_first_error(blocks, 4, [&](long b) {
    const std::size_t i0 = static_cast<std::size_t>(b) * kBlock, i1 = std::min(n, i0 + kBlock);
    std::copy(trial_.begin() + static_cast<std::ptrdiff_t>(i0),
              trial_.begin() + static_cast<std::ptrdiff_t>(i1),
              committed_.begin() + static_cast<std::ptrdiff_t>(i0));
  });
}

double MaterialContribution::dissipated_work() const {
  double wp = 0.0;
  // W_p = sum_q w_p(history_q) det J w
  for (std::size_t e = 0; e < element_law_.size(); ++e) {
    if (element_law_[e]->state_size() == 0) continue;
    if (failure_offset_ != kNoFailure && eroded(e)) continue;  // in eroded_energy()
    for (std::size_t q = qp_offset_[e]; q < qp_offset_[e + 1]; ++q) {
      wp += element_law_[e]->plastic_work_density(
                std::span<const double>(committed_)
                    .subspan(state_offset_[q], state_offset_[q + 1] - state_offset_[q])) *
            weight_[q];
    }
  }
  return wp;
}

double MaterialContribution::element_plastic_work(std::size_t e) const {
  double wp = 0.0;
  if (element_law_[e]->state_size() == 0) return wp;
  for (std::size_t q = qp_offset_[e]; q < qp_offset_[e + 1]; ++q) {
    wp += element_law_[e]->plastic_work_density(std::span<const double>(committed_).subspan(
              state_offset_[q], state_offset_[q + 1] - state_offset_[q])) *
          weight_[q];
  }
  return wp;
}

double MaterialContribution::element_plastic_strain(std::size_t e) const {
  double sum = 0.0;
  for (std::size_t q = qp_offset_[e]; q < qp_offset_[e + 1]; ++q) {
    sum += element_law_[e]->equivalent_plastic_strain(std::span<const double>(committed_).subspan(
        state_offset_[q], state_offset_[q + 1] - state_offset_[q]));
  }
  return sum / static_cast<double>(qp_offset_[e + 1] - qp_offset_[e]);
}

double MaterialContribution::failure_time(std::size_t e) const {
  return failure_offset_ == kNoFailure ? -1.0 : committed_[failure_offset_ + e];
}

std::size_t MaterialContribution::num_failed() const {
  std::size_t n = 0;
  for (std::size_t e = 0; e < mesh_.num_elements(); ++e) n += failed(e) ? 1 : 0;
  return n;
}

double MaterialContribution::eroded_energy() const {
  return failure_offset_ == kNoFailure ? 0.0 : committed_[failure_offset_ + mesh_.num_elements()];
}

void MaterialContribution::add_eroded_energy(double w) {
  if (failure_offset_ == kNoFailure) return;
  const std::size_t i = failure_offset_ + mesh_.num_elements();
  committed_[i] += w;
  trial_[i] = committed_[i];
}

std::vector<std::size_t> MaterialContribution::update_failures(double time) {
  std::vector<std::size_t> newly;
  if (failure_offset_ == kNoFailure) return newly;
  // failed when the committed mean eps_p over the element's points reaches eps_f
  for (std::size_t e = 0; e < mesh_.num_elements(); ++e) {
    if (failed(e) || !(element_plastic_strain(e) >= element_failure_strain_[e])) continue;
    committed_[failure_offset_ + e] = trial_[failure_offset_ + e] = time;
    newly.push_back(e);
    // erosion: its strain energy (at the committed u) and plastic work leave with it
    if (element_erodes_[e] != 0) add_eroded_energy(element_energy_[e] + element_plastic_work(e));
  }
  return newly;
}

void MaterialContribution::set_committed_state(const std::vector<double>& state) {
  if (state.size() != committed_.size()) {
    throw Error("material contribution: a quadrature-point history of " +
                std::to_string(state.size()) + " values was given, this model has " +
                std::to_string(committed_.size()) + " (state of another model?)");
  }
  committed_ = state;
  trial_ = state;
}


// ---- reduced Hex8 (Hex8Formulation::Reduced): the explicit plate element ----
// Points: one in the plane, a line through the thickness (thickness_line_rule). The line sees
// every displacement mode of the Hex8 but the two hourglass modes h_1 = xi eta and
// h_4 = xi eta zeta (xi, eta in the plane, zeta through the thickness) in each of the three
// components: their gradients vanish on the line. These get the stabilisation of Flanagan &
// Belytschko (IJNME 17, 1981, 679-706): the projections gamma = h - G0 (X^T h) (G0 the
// gradients at the centre, X the nodes' coordinates) are orthogonal to every linear field (so
// the patch test and rigid motions, rotations of any size included, give no hourglass force),
// hourglass "strains" q_alpha = U^T gamma_alpha (3-vectors) and forces f_a = gamma_alpha,a
// K_alpha q_alpha. The stiffnesses K_alpha are those of the assumed strains of Belytschko &
// Bindeman (CMAME 105, 1993, 225-260): the energy of the mode's normal strains, which is that
// of bending in the plane (h_1 in the in-plane components: exact for a rectangle) and of the
// thickness strain's xi eta variation (h_4 normal to the plane), without the shear strains
// whose integration would lock:
//   K_1 = V / 192 E' (g_xi g_xi^T + g_eta g_eta^T),
//   K_4 = V / 576 [E' (g_xi g_xi^T + g_eta g_eta^T) + (lambda + 2 mu) g_zeta g_zeta^T],
// g the gradients of the parametric coordinates at the centre, n the plate's normal,
// E' = 4 mu (lambda + mu) / (lambda + 2 mu) the plate modulus. The line misses one more
// displacement mode: a rotation about the normal that varies through the thickness
// (u = zeta (-eta, xi, 0): torsion), whose strains are transverse shears that vary in the plane.
// So the transverse shears' in-plane variations, s_eta = d gamma_(xi n) / d eta and
// s_xi = d gamma_(eta n) / d xi at the centre (computed from the projected vectors), get their
// energy int mu (eta s_eta)^2 + mu (xi s_xi)^2 dV = mu V / 3 (s_eta^2 + s_xi^2): the part of the
// transverse shear that assumed-natural-strain plates keep (MITC4: gamma_(xi n) linear in eta),
// zero for a Kirchhoff twist (its rotations and w = xi eta cancel), while d gamma_(xi n) / d xi,
// which would lock in bending, is left out. This also holds w = xi eta (h_1 normal to the
// plane). The hourglass forces are elastic (as LS-DYNA's stiffness forms), in the reference frame
// (total Lagrangian: exact for rigid rotations, approximate for large rotations with hourglass
// deformation).
// Poisson thickness locking: with one element through the thickness the displacement field's
// thickness strain is constant through it, so bending (whose Poisson contraction varies
// linearly through it) would see a plane-strain modulus (+10 % at nu = 0.3). One enhanced
// strain (Simo & Armero 1992; the thickness mode of the solid-shells of Hauptmann &
// Schweizerhof, IJNME 42, 1998, 49-69) adds F += beta (j0 / j) zeta n (x) c, c = grad zeta at the
// centre (int over the element = 0: the patch test holds). Explicit steps update it once per
// step with the elastic K_bb = (lambda + 2 mu) |c|^2 sum_q w_q ((j0 / j) zeta_q)^2 (factorised at
// construction; the law called without its tangent):
//   beta_n+1 = beta_n - h(u_n+1, beta_n) / K_bb,  h = sum_q w_q n . P_q c (j0 / j) zeta_q,
// so h goes to zero with the steps (exactly for a linear law, geometrically while plastic flow
// softens the thickness stiffness).
void MaterialContribution::setup_reduced_hex8(const ElementCoordinates& x, int thickness_axis,
                                              const Mat3& j0_inv, const Vec3& elastic) {
  static constexpr double kCorner[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                           {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  const int k = thickness_axis, i = (k + 1) % 3, j = (k + 2) % 3;
  ShapeVector n;
  ShapeGradient g;
  physical_gradients(ElementType::Hex8, x, Vec3::Zero(), n, g);
  const Eigen::Matrix<double, 8, 3> g0 = g.topRows(8);
  const Eigen::Matrix<double, 8, 3> xe = x.topRows(8);
  Eigen::Matrix<double, 8, 1> h1, h4;
  for (int a = 0; a < 8; ++a) {
    h1[a] = kCorner[a][i] * kCorner[a][j];
    h4[a] = h1[a] * kCorner[a][k];
  }
  // gamma = v - G0 (X^T v): orthogonal to every linear field (X^T G0 = I, sum_a G0_a = 0)
  auto project = [&](const Eigen::Matrix<double, 8, 1>& v) -> Eigen::Matrix<double, 8, 1> {
    return v - g0 * (xe.transpose() * v);
  };
  Eigen::Matrix<double, 8, 1> h_jk, h_ik;  // eta zeta, xi zeta (xi = axis i, eta = axis j)
  for (int a = 0; a < 8; ++a) {
    h_jk[a] = kCorner[a][j] * kCorner[a][k];
    h_ik[a] = kCorner[a][i] * kCorner[a][k];
  }
  const Eigen::Matrix<double, 8, 1> gamma1 = project(h1), gamma4 = project(h4);
  const Eigen::Matrix<double, 8, 1> gamma_jk = project(h_jk), gamma_ik = project(h_ik);
  const Vec3 gi = j0_inv.row(i).transpose(), gj = j0_inv.row(j).transpose(),
             gk = j0_inv.row(k).transpose();
  const Vec3 normal = gk.normalized(), ti = gi.normalized(), tj = gj.normalized();
  const double l2m = elastic[0], lambda = elastic[1], mu = elastic[2];
  const double plate = l2m - lambda * lambda / l2m;
  const std::size_t q0 = qp_offset_.back(), q1 = weight_.size();
  double volume = 0.0, beta = 0.0;
  for (std::size_t q = q0; q < q1; ++q) {
    volume += weight_[q];
    beta += weight_[q] * reduced_point_scale_[q] * reduced_point_scale_[q];
  }
  const Mat3 membrane = plate * (gi * gi.transpose() + gj * gj.transpose());
  const Mat3 k1 = volume / 192.0 * membrane;
  const Mat3 k4 = volume / 576.0 * (membrane + l2m * gk * gk.transpose());
  const double k_beta = l2m * gk.squaredNorm() * beta;
  // the transverse shears' in-plane variation: s_eta = d gamma_(xi n) / d eta and
  // s_xi = d gamma_(eta n) / d xi at the centre, s = sum_a c_a . u_a with
  // d grad N_a / d eta = (gamma1_a g_xi + gamma_jk_a g_zeta) / 8 (and i <-> j)
  Eigen::Matrix<double, 8, 3> c_eta, c_xi;
  for (int a = 0; a < 8; ++a) {
    const Vec3 b_eta = (gamma1[a] * gi + gamma_jk[a] * gk) / 8.0;
    const Vec3 b_xi = (gamma1[a] * gj + gamma_ik[a] * gk) / 8.0;
    c_eta.row(a) = (ti * normal.dot(b_eta) + normal * ti.dot(b_eta)).transpose();
    c_xi.row(a) = (tj * normal.dot(b_xi) + normal * tj.dot(b_xi)).transpose();
  }
  for (int a = 0; a < 8; ++a) reduced_data_.push_back(gamma1[a]);
  for (int a = 0; a < 8; ++a) reduced_data_.push_back(gamma4[a]);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) reduced_data_.push_back(k1(r, c));
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) reduced_data_.push_back(k4(r, c));
  for (int d = 0; d < 3; ++d) reduced_data_.push_back(gk[d]);
  for (int d = 0; d < 3; ++d) reduced_data_.push_back(normal[d]);
  for (int a = 0; a < 8; ++a)
    for (int d = 0; d < 3; ++d) reduced_data_.push_back(c_eta(a, d));
  for (int a = 0; a < 8; ++a)
    for (int d = 0; d < 3; ++d) reduced_data_.push_back(c_xi(a, d));
  // int mu (eta s_eta)^2 dV = mu V / 3 s_eta^2
  reduced_data_.push_back(mu * volume / 3.0);
  reduced_data_.push_back(1.0 / k_beta);
}

void MaterialContribution::evaluate_reduced(std::size_t e, const ElementDisplacements& ue,
                                            ElementVector& fe, ElementMatrix* ke,
                                            double& energy, ElementVector& fabs) {
  if (ke != nullptr)
    throw Error(
        "the reduced Hex8 (hex8: reduced) has no tangent: it is an element of central-difference "
        "analyses (without stiffness-proportional Rayleigh damping); static and Newmark "
        "analyses use the EAS Hex8 (hex8: incompatible-modes)");
  using Gradients = Eigen::Matrix<double, 8, 3, Eigen::RowMajor>;
  const MaterialLaw& law = *element_law_[e];
  const double* data = reduced_data_.data() + reduced_start_[e];
  const Eigen::Map<const Eigen::Matrix<double, 8, 1>> gamma1(data), gamma4(data + 8);
  const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> k1(data + 16), k4(data + 25);
  const Eigen::Map<const Vec3> c(data + 34), normal(data + 37);
  const Eigen::Map<const Eigen::Matrix<double, 8, 3, Eigen::RowMajor>> c_eta(data + 40),
      c_xi(data + 64);
  const double k_shear = data[88];
  const double k_beta_inverse = data[89];
  const std::size_t a0 = eas_offset_[e];
  const double beta = committed_[a0];
  const Eigen::Matrix<double, 8, 3> un = ue.topRows(8);
  const Mat3 enhanced = beta * normal * c.transpose();
  MaterialResponse resp;
  Eigen::Matrix<double, 8, 3> forces = Eigen::Matrix<double, 8, 3>::Zero();
  double h = 0.0;
  for (std::size_t q = qp_offset_[e]; q < qp_offset_[e + 1]; ++q) {
    const Eigen::Map<const Gradients> g(gradients_.data() + gradient_offset_[q]);
    const double zeta = reduced_point_scale_[q];
    // F = I + sum_a u_a (x) grad_X N_a + beta (j0 / j) zeta n (x) c
    const Mat3 f = Mat3::Identity() + un.transpose() * g + zeta * enhanced;
    if (!law.small_strain()) require_not_inverted(e, f.determinant());
    const std::size_t s0 = state_offset_[q], ns = state_offset_[q + 1] - s0;
    law.evaluate_stress(f, std::span<const double>(committed_).subspan(s0, ns),
                        std::span<double>(trial_).subspan(s0, ns), resp);
    const double w = weight_[q];
    energy += resp.energy_density * w;
    forces.noalias() += g * (resp.stress.transpose() * w);
    h += w * zeta * normal.dot(resp.stress * c);
    const double dp = stress_round_off(resp.stress, f, element_modulus_[e]) * w;
    const double* gn = gradient_norms_.data() + gradient_offset_[q] / 3;
    for (int a = 0; a < 8; ++a) fabs[a] += gn[a] * dp;
    const Mat3 sigma = cauchy_stress_of(law, resp.stress, f);
    const auto qi = static_cast<Eigen::Index>(q);
    cauchy_.row(qi) << sigma(0, 0), sigma(1, 1), sigma(2, 2), sigma(0, 1), sigma(1, 2),
        sigma(0, 2);
    eqps_[qi] = law.equivalent_plastic_strain(std::span<const double>(trial_).subspan(s0, ns));
  }
  trial_[a0] = beta - h * k_beta_inverse;
  // the enhanced strain's work since the last evaluation: -1/2 (h_k + h_k+1)(beta_k - beta_k-1),
  // beta_k - beta_k-1 = -h_k / K_bb (enhanced_strain_work())
  const double h_before = committed_[a0 + 1];
  trial_[a0 + 1] = h;
  enhanced_work_trial_[e] = 0.5 * (h_before + h) * h_before * k_beta_inverse;
  // hourglass: q_alpha = U^T gamma_alpha, f_a += gamma_alpha,a K_alpha q_alpha
  const Vec3 q1 = un.transpose() * gamma1, q4 = un.transpose() * gamma4;
  const Vec3 p1 = k1 * q1, p4 = k4 * q4;
  forces.noalias() += gamma1 * p1.transpose() + gamma4 * p4.transpose();
  // transverse shear's in-plane variation: f_a += k_s (s_eta c_eta,a + s_xi c_xi,a)
  const double s_eta = (c_eta.array() * un.array()).sum(), s_xi = (c_xi.array() * un.array()).sum();
  forces.noalias() += k_shear * (s_eta * c_eta + s_xi * c_xi);
  energy += 0.5 * (q1.dot(p1) + q4.dot(p4) + k_shear * (s_eta * s_eta + s_xi * s_xi));
  for (int a = 0; a < 8; ++a) fe.segment<3>(3 * a) = forces.row(a).transpose();
}

}  // namespace partita::fem
