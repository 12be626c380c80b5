#include "partita/coupling/acceleration/iqn_ils.hpp"

#include <cmath>

#include "partita/interface/state_archive.hpp"
#include "partita/interface/error.hpp"

namespace partita::coupling {

IqnIls::IqnIls(Options options) : options_(options) {
  if (!(options_.initial_relaxation > 0.0 && options_.initial_relaxation <= 1.0))
    throw Error("IQN-ILS initial relaxation must satisfy 0 < omega <= 1, found " +
                std::to_string(options_.initial_relaxation));
  if (options_.max_columns < 1) throw Error("IQN-ILS needs max_columns >= 1");
  if (options_.reused_windows < 0) throw Error("IQN-ILS needs reused_windows >= 0");
  window_columns_.push_front(0);
}

void IqnIls::erase_column(Eigen::Index j) {
  const Eigen::Index n = v_.cols();
  if (j + 1 < n) {
    v_.middleCols(j, n - j - 1) = v_.rightCols(n - j - 1).eval();
    w_.middleCols(j, n - j - 1) = w_.rightCols(n - j - 1).eval();
  }
  v_.conservativeResize(Eigen::NoChange, n - 1);
  w_.conservativeResize(Eigen::NoChange, n - 1);
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

void IqnIls::remove_column(Eigen::Index j) {
  erase_column(j);
  if (qr_.cols() > j) qr_.delete_column(j);
}

void IqnIls::clear(Eigen::Index rows) {
  v_.resize(rows, 0);
  w_.resize(rows, 0);
  for (auto& c : window_columns_) c = 0;
  qr_.reset(rows);
  qr_weights_.resize(0);
}

void IqnIls::rebuild(const Eigen::VectorXd& weights) {
  // QR of D V by appending the columns newest first (insert_column at the back: no rotations);
  // with QR2 a column whose orthogonal part is below the limit is dropped on the way.
  ++rebuilds_;
  qr_.reset(v_.rows());
  qr_weights_ = weights;
  const double limit = options_.filter == Filter::qr2 ? options_.filter_limit : 0.0;
  for (Eigen::Index j = 0; j < v_.cols();) {
    if (qr_.append(weights.cwiseProduct(v_.col(j)), limit)) {
      ++j;
    } else {
      erase_column(j);
      ++filtered_;
    }
  }
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

void IqnIls::add_columns(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                         const Eigen::VectorXd& weights) {
  const Eigen::VectorXd r = x_tilde - x;
  if (!first_iteration_ && previous_residual_.size() == r.size()) {
    // V = [r_k - r_{k-1}, ...], W = [H(x_k) - H(x_{k-1}), ...], newest first
    const Eigen::Index n = v_.cols();
    Eigen::MatrixXd v(r.size(), n + 1), w(r.size(), n + 1);
    v.col(0) = r - previous_residual_;
    w.col(0) = x_tilde - previous_x_tilde_;
    if (n > 0) {
      v.rightCols(n) = v_;
      w.rightCols(n) = w_;
    }
    ++window_columns_.front();
    if (qr_.insert_column(0, weights.cwiseProduct(v.col(0)))) {
      v_.swap(v);
      w_.swap(w);
    } else {
      // zero, or dependent on the columns in to rounding: not a usable secant
      --window_columns_.front();
      ++filtered_;
    }
    while (v_.cols() > options_.max_columns) remove_column(v_.cols() - 1);
  }
  previous_residual_ = r;
  previous_x_tilde_ = x_tilde;
}

void IqnIls::apply_filter() {
  // On the updated factorisation: removing column j updates R for the columns after it, so each
  // test sees the columns that are still in (as a rebuild newest first would).
  if (options_.filter == Filter::qr2) {
    for (Eigen::Index j = 0; j < qr_.cols();) {
      if (std::abs(qr_.diagonal(j)) < options_.filter_limit * qr_.column_norm(j)) {
        remove_column(j);
        ++filtered_;
      } else {
        ++j;
      }
    }
  } else if (options_.filter == Filter::qr1) {
    bool again = true;
    while (again) {
      again = false;
      const double rn = qr_.r_norm();
      for (Eigen::Index j = 0; j < qr_.cols(); ++j) {
        if (std::abs(qr_.diagonal(j)) < options_.filter_limit * rn) {
          remove_column(j);
          ++filtered_;
          again = true;
          break;
        }
      }
    }
  }
}

void IqnIls::accelerate(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                        const Eigen::VectorXd& weights, Eigen::VectorXd& next) {
  if (v_.rows() != x.size()) clear(x.size());  // the data changed size: start over
  match_weights(weights);
  add_columns(x, x_tilde, weights);
  first_iteration_ = false;
  if (v_.cols() > 0) apply_filter();
  if (v_.cols() == 0) {
    // no model yet: x_{k+1} = x_k + ω_0 r_k
    next = x + options_.initial_relaxation * (x_tilde - x);
    return;
  }
  // c = argmin |D (V c + r_k)|;  x_{k+1} = H(x_k) + W c
  const Eigen::VectorXd c = qr_.solve(-weights.cwiseProduct(x_tilde - x));
  next = x_tilde + w_ * c;
}

void IqnIls::window_converged(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                              const Eigen::VectorXd& weights) {
  // The converged iteration's differences belong to the model too (preCICE adds them here).
  if (v_.rows() == x.size() || v_.cols() == 0) {
    if (v_.rows() != x.size()) clear(x.size());
    match_weights(weights);
    add_columns(x, x_tilde, weights);
  }
  first_iteration_ = true;
  // Keep the columns of the current window and `reused_windows` before it (deleting the last
  // column of the factorisation needs no rotation).
  window_columns_.push_front(0);
  while (static_cast<int>(window_columns_.size()) > options_.reused_windows + 1) {
    const int count = window_columns_.back();
    window_columns_.pop_back();
    for (int i = 0; i < count; ++i) {
      const Eigen::Index last = v_.cols() - 1;
      v_.conservativeResize(Eigen::NoChange, last);
      w_.conservativeResize(Eigen::NoChange, last);
      if (qr_.cols() > last) qr_.delete_column(last);
    }
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
