#include "partita/coupling/acceleration/quasi_newton.hpp"

#include <cmath>
#include <string>

#include "partita/interface/error.hpp"

namespace partita::coupling {

QuasiNewtonAcceleration::QuasiNewtonAcceleration(const std::string& label, Settings settings)
    : settings_(settings) {
  if (!(settings_.initial_relaxation > 0.0 && settings_.initial_relaxation <= 1.0))
    throw Error(label + " initial relaxation must satisfy 0 < omega <= 1, found " +
                std::to_string(settings_.initial_relaxation));
  if (settings_.max_columns < 1) throw Error(label + " needs max_columns >= 1");
}

void QuasiNewtonAcceleration::start_over(Eigen::Index rows) {
  v_.resize(rows, 0);
  w_.resize(rows, 0);
  qr_.reset(rows);
  qr_weights_.resize(0);
}

void QuasiNewtonAcceleration::erase_column(Eigen::Index j) {
  const Eigen::Index n = v_.cols();
  if (j + 1 < n) {
    v_.middleCols(j, n - j - 1) = v_.rightCols(n - j - 1).eval();
    w_.middleCols(j, n - j - 1) = w_.rightCols(n - j - 1).eval();
  }
  v_.conservativeResize(Eigen::NoChange, n - 1);
  w_.conservativeResize(Eigen::NoChange, n - 1);
  column_erased(j);
}

void QuasiNewtonAcceleration::remove_column(Eigen::Index j) {
  erase_column(j);
  if (qr_.cols() > j) qr_.delete_column(j);
}

void QuasiNewtonAcceleration::factorise(const Eigen::VectorXd& weights, double limit) {
  qr_.reset(v_.rows());
  qr_weights_ = weights;
  for (Eigen::Index j = 0; j < v_.cols();) {
    if (qr_.append(weights.cwiseProduct(v_.col(j)), limit)) {
      ++j;
    } else {
      erase_column(j);
      ++filtered_;
    }
  }
}

void QuasiNewtonAcceleration::insert_secant(const Eigen::VectorXd& x,
                                            const Eigen::VectorXd& x_tilde,
                                            const Eigen::VectorXd& weights) {
  const Eigen::VectorXd r = x_tilde - x;
  if (!first_iteration_ && previous_residual_.size() == r.size()) {
    // V = [r_k - r_{k-1}, ...], W = [H(x_k) - H(x_{k-1}), ...], newest first
    const Eigen::VectorXd dv = r - previous_residual_;
    if (qr_.insert_column(0, weights.cwiseProduct(dv))) {
      const Eigen::Index n = v_.cols();
      Eigen::MatrixXd v(r.size(), n + 1), w(r.size(), n + 1);
      v.col(0) = dv;
      w.col(0) = x_tilde - previous_x_tilde_;
      if (n > 0) {
        v.rightCols(n) = v_;
        w.rightCols(n) = w_;
      }
      v_.swap(v);
      w_.swap(w);
      column_inserted();
    } else {
      ++filtered_;  // zero, or dependent on the columns in to rounding: not a usable secant
    }
    while (v_.cols() > settings_.max_columns) remove_column(v_.cols() - 1);
  }
  previous_residual_ = r;
  previous_x_tilde_ = x_tilde;
}

void QuasiNewtonAcceleration::update_difference_matrices(const Eigen::VectorXd& x,
                                                         const Eigen::VectorXd& x_tilde,
                                                         const Eigen::VectorXd& weights) {
  if (v_.rows() != x.size()) start_over(x.size());  // the data changed size
  match_weights(weights);
  insert_secant(x, x_tilde, weights);
}

void QuasiNewtonAcceleration::apply_filter() {
  // On the updated factorisation: removing column j updates R for the columns after it, so each
  // test sees the columns that are still in (as a factorisation newest first would).
  if (settings_.filter == Filter::qr2) {
    for (Eigen::Index j = 0; j < qr_.cols();) {
      if (std::abs(qr_.diagonal(j)) < settings_.filter_limit * qr_.column_norm(j)) {
        remove_column(j);
        ++filtered_;
      } else {
        ++j;
      }
    }
  } else if (settings_.filter == Filter::qr1) {
    bool again = true;
    while (again) {
      again = false;
      const double rn = qr_.r_norm();
      for (Eigen::Index j = 0; j < qr_.cols(); ++j) {
        if (std::abs(qr_.diagonal(j)) < settings_.filter_limit * rn) {
          remove_column(j);
          ++filtered_;
          again = true;
          break;
        }
      }
    }
  }
}

void QuasiNewtonAcceleration::accelerate(const Eigen::VectorXd& x, const Eigen::VectorXd& x_tilde,
                                         const Eigen::VectorXd& weights, Eigen::VectorXd& next) {
  update_difference_matrices(x, x_tilde, weights);
  first_iteration_ = false;
  apply_filter();
  const Eigen::VectorXd r = x_tilde - x;
  if (!has_model()) {
    next = x + settings_.initial_relaxation * r;  // no model yet: x_{k+1} = x_k + omega_0 r_k
    return;
  }
  quasi_newton_step(x, x_tilde, r, weights, next);
}

}  // namespace partita::coupling
