#include "partita/coupling/acceleration/iqn_ils.hpp"

#include <cmath>

#include "partita/interface/state_archive.hpp"
#include "partita/interface/error.hpp"

namespace partita::coupling {

IqnIls::IqnIls(Options options)
    : QuasiNewtonAcceleration(
          "IQN-ILS", {options.initial_relaxation, options.max_columns, options.filter,
                      options.filter_limit}),
      reused_windows_(options.reused_windows) {
  if (reused_windows_ < 0) throw Error("IQN-ILS needs reused_windows >= 0");
  window_columns_.push_front(0);
}

void IqnIls::column_erased(Eigen::Index j) {
  // Which window owned column j (windows hold consecutive columns, current window first)?
  Eigen::Index first = 0;
  for (auto& count : window_columns_) {
    if (j < first + count) {
      --count;
      return;
    }
    first += count;
  }
}

void IqnIls::start_over(Eigen::Index rows) {
  QuasiNewtonAcceleration::start_over(rows);
  for (auto& c : window_columns_) c = 0;
}

void IqnIls::rebuild(const Eigen::VectorXd& weights) {
  // with QR2 a column whose orthogonal part is below the limit is dropped on the way
  ++rebuilds_;
  factorise(weights, settings_.filter == Filter::qr2 ? settings_.filter_limit : 0.0);
}

void IqnIls::match_weights(const Eigen::VectorXd& weights) {
  if (qr_weights_.size() != weights.size() || qr_.cols() != v_.cols() || qr_.rows() != v_.rows()) {
    rebuild(weights);
    return;
  }
  if (qr_weights_ == weights) return;
  // D' = s D (one accelerated field, or fields scaled alike): D' V = Q (s R).
  const double s = weights(0) / qr_weights_(0);
  if (std::isfinite(s) && s > 0.0 &&
      (weights - s * qr_weights_).lpNorm<Eigen::Infinity>() <=
          1e-14 * weights.lpNorm<Eigen::Infinity>()) {
    qr_.scale(s);
    qr_weights_ = weights;
    return;
  }
  rebuild(weights);
}

void IqnIls::quasi_newton_step(const Eigen::VectorXd& /*x*/, const Eigen::VectorXd& x_tilde,
                               const Eigen::VectorXd& r, const Eigen::VectorXd& weights,
                               Eigen::VectorXd& next) {
  // c = argmin |D (V c + r_k)|;  x_{k+1} = H(x_k) + W c
  const Eigen::VectorXd c = least_squares(r, weights);
  next = x_tilde + w_ * c;
}

void IqnIls::window_converged(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                              const Eigen::VectorXd& weights) {
  // The converged iteration's differences belong to the model too (preCICE adds them here).
  if (v_.rows() == x.size() || v_.cols() == 0) update_difference_matrices(x, x_tilde, weights);
  first_iteration_ = true;
  // Keep the columns of the current window and `reused_windows` before it (deleting the last
  // column of the factorisation needs no rotation).
  window_columns_.push_front(0);
  while (static_cast<int>(window_columns_.size()) > reused_windows_ + 1) {
    for (int i = window_columns_.back(); i > 0; --i) remove_column(v_.cols() - 1);
    window_columns_.pop_back();
  }
}

std::shared_ptr<const config::Spec> IqnIls::spec() {
  auto s = std::make_shared<config::Spec>(
      "iqn-ils",
      "interface quasi-Newton, inverse Jacobian from a least-squares model (Degroote et al. 2009)");
  s->string("type", "the acceleration's name").required();
  s->real("initial_relaxation", "relaxation factor while there are no columns (first iteration)")
      .min(0.0, true)
      .max(1.0)
      .def(0.1);
  s->integer("max_columns", "most columns kept in V and W (oldest dropped first)").min(1).def(50);
  s->integer("reused_windows", "past windows whose columns are kept").non_negative().def(8);
  s->choice("filter", "filter of nearly dependent columns", {"none", "qr1", "qr2"}).def("qr2");
  s->real("filter_limit", "limit of the filter").positive().def(1e-3);
  declare_accelerated_data(*s);
  return s;
}

std::unique_ptr<Acceleration> IqnIls::create(const config::Node& node) {
  Options o;
  o.initial_relaxation = node.real("initial_relaxation");
  o.max_columns = static_cast<int>(node.integer("max_columns"));
  o.reused_windows = static_cast<int>(node.integer("reused_windows"));
  const std::string f = node.string("filter");
  o.filter = f == "qr1" ? Filter::qr1 : f == "qr2" ? Filter::qr2 : Filter::none;
  o.filter_limit = node.real("filter_limit");
  return std::make_unique<IqnIls>(o);
}

void IqnIls::serialize(StateArchive& ar) {
  ar.section("iqn-ils");
  ar.io(v_);
  ar.io(w_);
  std::vector<int> counts(window_columns_.begin(), window_columns_.end());  // (a deque)
  ar.io(counts);
  if (ar.reading()) window_columns_.assign(counts.begin(), counts.end());
  ar.io(previous_residual_);
  ar.io(previous_x_tilde_);
  ar.io(first_iteration_);
  qr_.serialize(ar);
  ar.io(qr_weights_);
  ar.io(filtered_);
  ar.io(rebuilds_);
  if (ar.reading() && (v_.cols() != w_.cols() || v_.rows() != w_.rows()))
    ar.fail("V and W of equal shape");
}

}  // namespace partita::coupling
