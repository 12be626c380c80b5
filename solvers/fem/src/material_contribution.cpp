#include "partita/fem/material_contribution.hpp"

#include <algorithm>
#include <array>
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
    if (c.uses_damage()) {
      // RTCL and BWH: the element's criterion, and its plate's normal (BWH)
      if (element_damage_criterion_.empty()) {
        element_damage_criterion_.assign(mesh_.num_elements(), nullptr);
        element_normal_.assign(mesh_.num_elements(), Vec3::Zero());
      }
      const auto r = static_cast<std::size_t>(el.region);
      if (region_damage_criteria_.size() <= r) region_damage_criteria_.resize(r + 1);
      if (!region_damage_criteria_[r]) region_damage_criteria_[r] = std::make_unique<FailureCriterion>(c);
      element_damage_criterion_[e] = region_damage_criteria_[r].get();
      if (c.kind == FailureCriterion::Kind::Bwh) element_normal_[e] = failure_plate_normal(mesh_, el);
    }
  }
  if (failure_offset_ != kNoFailure) alpha_end += mesh_.num_elements() + 1;
  // RTCL and BWH: per point its damage and the eps_p at which it was last updated
  if (!element_damage_criterion_.empty()) {
    damage_offset_ = alpha_end;
    alpha_end += 2 * weight_.size();
  }
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

void MaterialContribution::commit() {
  committed_time_ = trial_time_;
  step_.time_increment = 0.0;
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

double MaterialContribution::element_damage(std::size_t e) const {
  if (damage_offset_ == kNoFailure || element_damage_criterion_[e] == nullptr) return -1.0;
  double sum = 0.0;
  for (std::size_t q = qp_offset_[e]; q < qp_offset_[e + 1]; ++q)
    sum += committed_[damage_offset_ + 2 * q];
  return sum / static_cast<double>(qp_offset_[e + 1] - qp_offset_[e]);
}

void MaterialContribution::update_damage() {
  // each point's damage from the committed step: the stress of the last add() (at the
  // committed u) and the increment of its committed eps_p since the last update
  for (std::size_t e = 0; e < mesh_.num_elements(); ++e) {
    const FailureCriterion* c = element_damage_criterion_[e];
    if (c == nullptr || failed(e)) continue;
    for (std::size_t q = qp_offset_[e]; q < qp_offset_[e + 1]; ++q) {
      const double eps_p = element_law_[e]->equivalent_plastic_strain(
          std::span<const double>(committed_)
              .subspan(state_offset_[q], state_offset_[q + 1] - state_offset_[q]));
      const std::size_t at = damage_offset_ + 2 * q;
      const auto row = cauchy_.row(static_cast<Eigen::Index>(q));
      Mat3 sigma;
      sigma << row[0], row[3], row[5], row[3], row[1], row[4], row[5], row[4], row[2];
      const double d = c->updated_damage(committed_[at], sigma, eps_p - committed_[at + 1],
                                         element_failure_strain_[e], element_normal_[e]);
      committed_[at] = trial_[at] = d;
      committed_[at + 1] = trial_[at + 1] = eps_p;
    }
  }
}

std::vector<std::size_t> MaterialContribution::update_failures(double time) {
  std::vector<std::size_t> newly;
  if (failure_offset_ == kNoFailure) return newly;
  if (damage_offset_ != kNoFailure) update_damage();
  // failed when the committed mean eps_p over the element's points reaches eps_f (RTCL, BWH:
  // when the mean damage reaches 1)
  for (std::size_t e = 0; e < mesh_.num_elements(); ++e) {
    if (failed(e)) continue;
    if (damage_offset_ != kNoFailure && element_damage_criterion_[e] != nullptr) {
      if (!(element_damage(e) >= 1.0)) continue;
    } else if (!(element_plastic_strain(e) >= element_failure_strain_[e])) {
      continue;
    }
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

}  // namespace partita::fem
