#include "partita/coupling/acceleration/iqn_imvj.hpp"

#include <cmath>
#include <string>

#include <Eigen/QR>
#include <Eigen/SVD>

#include "partita/interface/state_archive.hpp"
#include "partita/interface/error.hpp"

namespace partita::coupling {

IqnImvj::IqnImvj(Options options)
    : QuasiNewtonAcceleration(
          "IQN-IMVJ", {options.initial_relaxation, options.max_columns, options.filter,
                       options.filter_limit}),
      restart_(options.restart),
      chunk_size_(options.chunk_size),
      truncation_(options.truncation) {
  if (chunk_size_ < 1) throw Error("IQN-IMVJ needs chunk_size >= 1");
  if (!(truncation_ >= 0.0 && truncation_ < 1.0))
    throw Error("IQN-IMVJ truncation must satisfy 0 <= truncation < 1, found " +
                std::to_string(truncation_));
}

void IqnImvj::start_over(Eigen::Index rows) {
  QuasiNewtonAcceleration::start_over(rows);
  a_.resize(rows, 0);
  b_.resize(rows, 0);
  windows_since_restart_ = 0;
}

void IqnImvj::match_weights(const Eigen::VectorXd& weights) {
  // The weights are fixed within a window; should they change, refactorise the (few) columns.
  if (qr_weights_.size() == weights.size() && qr_weights_ == weights && qr_.cols() == v_.cols())
    return;
  factorise(weights, 0.0);
}

Eigen::VectorXd IqnImvj::apply_previous_jacobian(const Eigen::VectorXd& y) const {
  if (a_.cols() == 0) return Eigen::VectorXd::Zero(y.size());
  return a_ * (b_.transpose() * y);
}

void IqnImvj::quasi_newton_step(const Eigen::VectorXd& /*x*/, const Eigen::VectorXd& x_tilde,
                                const Eigen::VectorXd& r, const Eigen::VectorXd& weights,
                                Eigen::VectorXd& next) {
  // x_{k+1} = H(x_k) + W c - J_prev (r_k + V c),  c = argmin |D (V c + r_k)|
  Eigen::VectorXd rest = r;
  next = x_tilde;
  if (v_.cols() > 0) {
    const Eigen::VectorXd c = least_squares(r, weights);
    next += w_ * c;
    rest += v_ * c;
  }
  if (a_.cols() > 0) next -= a_ * (b_.transpose() * rest);
}

void IqnImvj::window_converged(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                               const Eigen::VectorXd& weights) {
  // The converged iteration's differences belong to this window's secants too.
  update_difference_matrices(x, x_tilde, weights);
  apply_filter();
  first_iteration_ = true;
  const Eigen::Index m = v_.cols();
  if (m > 0) {
    // J_prev <- J_prev + (W - J_prev V) Z,  Z^T = D^2 V (V^T D^2 V)^{-1} = D Q R^{-T}
    Eigen::MatrixXd w_tilde = w_;
    if (a_.cols() > 0) w_tilde -= a_ * (b_.transpose() * v_);
    const Eigen::MatrixXd z_t =
        weights.asDiagonal() *
        qr_.r().triangularView<Eigen::Upper>().solve(qr_.q().transpose()).transpose();
    const Eigen::Index p = a_.cols();
    a_.conservativeResize(Eigen::NoChange, p + m);
    b_.conservativeResize(Eigen::NoChange, p + m);
    a_.rightCols(m) = w_tilde;
    b_.rightCols(m) = z_t;
  }
  // this window's secants live on in J_prev only
  QuasiNewtonAcceleration::start_over(x.size());
  if (++windows_since_restart_ >= chunk_size_) restart();
}

void IqnImvj::restart() {
  windows_since_restart_ = 0;
  if (a_.cols() == 0) return;
  ++restarts_;
  if (restart_ == Restart::zero) {
    a_.resize(a_.rows(), 0);
    b_.resize(b_.rows(), 0);
    return;
  }
  // A B^T = Qa (Ra Rb^T) Qb^T with thin QRs; Ra Rb^T = U S V^T (p x p); keep s_i > tau s_0.
  const Eigen::Index rows = a_.rows(), p = a_.cols();
  const Eigen::Index k = std::min(rows, p);
  Eigen::HouseholderQR<Eigen::MatrixXd> qa(a_), qb(b_);
  const Eigen::MatrixXd ra = qa.matrixQR().topRows(k).triangularView<Eigen::Upper>();
  const Eigen::MatrixXd rb = qb.matrixQR().topRows(k).triangularView<Eigen::Upper>();
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(ra * rb.transpose(),
                                        Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& s = svd.singularValues();
  Eigen::Index keep = 0;
  while (keep < s.size() && s(keep) > truncation_ * s(0) && s(keep) > 0.0) ++keep;
  const Eigen::MatrixXd q_a = qa.householderQ() * Eigen::MatrixXd::Identity(rows, k);
  const Eigen::MatrixXd q_b = qb.householderQ() * Eigen::MatrixXd::Identity(rows, k);
  a_ = q_a * (svd.matrixU().leftCols(keep) * s.head(keep).asDiagonal());
  b_ = q_b * svd.matrixV().leftCols(keep);
}

std::shared_ptr<const config::Spec> IqnImvj::spec() {
  auto s = std::make_shared<config::Spec>(
      "iqn-imvj",
      "interface quasi-Newton, inverse Jacobian from a multi-vector update carried across "
      "windows (Lindner et al. 2015; restarts after Scheufele & Mehl 2017)");
  s->string("type", "the acceleration's name").required();
  s->real("initial_relaxation",
          "relaxation factor of the first iteration, before any Jacobian information")
      .min(0.0, true)
      .max(1.0)
      .def(0.1);
  s->integer("max_columns", "most columns of one window in V and W (oldest dropped first)")
      .min(1)
      .def(50);
  s->choice("filter", "filter of nearly dependent columns", {"none", "qr2"}).def("qr2");
  s->real("filter_limit", "limit of the filter (stricter than IQN-ILS's: secants stay in J)")
      .positive()
      .def(1e-2);
  s->choice("restart",
            "every chunk_size windows: svd keeps the truncated SVD of the Jacobian, zero drops it",
            {"svd", "zero"})
      .def("svd");
  s->integer("chunk_size", "windows between restarts").min(1).def(8);
  s->real("truncation", "svd restart: singular values below this times the largest are dropped")
      .non_negative()
      .max(1.0, true)
      .def(1e-4);
  declare_accelerated_data(*s);
  return s;
}

std::unique_ptr<Acceleration> IqnImvj::create(const config::Node& node) {
  Options o;
  o.initial_relaxation = node.real("initial_relaxation");
  o.max_columns = static_cast<int>(node.integer("max_columns"));
  o.filter = node.string("filter") == "none" ? Filter::none : Filter::qr2;
  o.filter_limit = node.real("filter_limit");
  o.restart = node.string("restart") == "zero" ? Restart::zero : Restart::svd;
  o.chunk_size = static_cast<int>(node.integer("chunk_size"));
  o.truncation = node.real("truncation");
  return std::make_unique<IqnImvj>(o);
}

void IqnImvj::serialize(StateArchive& ar) {
  ar.section("iqn-imvj");
  ar.io(v_);
  ar.io(w_);
  qr_.serialize(ar);
  ar.io(qr_weights_);
  ar.io(previous_residual_);
  ar.io(previous_x_tilde_);
  ar.io(first_iteration_);
  ar.io(a_);
  ar.io(b_);
  ar.io(windows_since_restart_);
  ar.io(restarts_);
  ar.io(filtered_);
}

}  // namespace partita::coupling
