#include "balance_audit.hpp"

#include <algorithm>
#include <cmath>

#include "partita/coupling/elementwise.hpp"
#include "partita/interface/log.hpp"
#include "partita/run/run_summary.hpp"

namespace partita::run {

using namespace coupling;

namespace {

// The totals of each component of v (sums for extensive data, integrals over the point weights
// for intensive data) into `total`; where `magnitudes`, the same of the vector lengths |v_q|
// (the scale the imbalance is measured against) into `magnitude`; where u is given (a vector
// of the points' bound weights), sum_q u_q |v_q| into `bound`. One pass over the values.
// Vectors take the fused kernel; other component counts plain Eigen passes (the caller keeps
// `total` and `norm`: no allocation per window).
void totals(const Eigen::MatrixXd& v, const Mesh& mesh, bool extensive, bool magnitudes,
            const Eigen::VectorXd* u, Eigen::VectorXd& total, Eigen::ArrayXd& norm,
            double& magnitude, double& bound) {
  total.resize(v.cols());
  const double* w = extensive ? nullptr : mesh.weights().data();
  if (v.cols() == 3) {
    const elementwise::Totals3 t =
        elementwise::weighted_totals3(v.col(0).data(), v.col(1).data(), v.col(2).data(), w,
                                      v.rows(), magnitudes, u ? u->data() : nullptr);
    total = Eigen::Map<const Eigen::Vector3d>(t.total);
    magnitude = t.magnitude;
    bound = t.bound;
    return;
  }
  if (extensive)
    total.noalias() = v.colwise().sum().transpose();
  else
    total.noalias() = v.transpose() * mesh.weights();
  if (!magnitudes && !u) return;
  norm = v.rowwise().norm().array();
  magnitude = extensive ? norm.sum() : (norm * mesh.weights().array().abs()).sum();
  bound = u ? (norm * u->array()).sum() : 0.0;
}

}  // namespace

BalanceAudit::BalanceAudit(std::vector<const Exchange*> audited, double tolerance)
    : audited_(std::move(audited)), tolerance_(tolerance) {}

void BalanceAudit::observe(FinishedWindow& w) {
  if (w.initial()) return;
  compute();
  for (std::size_t i = 0; i < imbalance_.size(); ++i)
    if (imbalance_[i] > tolerance_) {
      ++warnings_;
      if (!warned_)
        log::get("coupling")
            ->warn(
                "window {} (t = {:.6g} s): exchange {} arrives off by {:.3g} of what was sent "
                "(coupling.balance_tolerance {:.3g}); the mapper does not conserve its total: "
                "use a conservative constraint or mapper (area-balanced for tractions); further "
                "windows are counted in the summary",
                w.window, w.time, audited_[i]->label(), imbalance_[i], tolerance_);
      warned_ = true;
    }
}

bool BalanceAudit::finite(const Exchange& e) const {
  const auto a = std::find(audited_.begin(), audited_.end(), &e);
  return a != audited_.end() && static_cast<std::size_t>(a - audited_.begin()) < finite_.size() &&
         finite_[static_cast<std::size_t>(a - audited_.begin())];
}

void BalanceAudit::compute() {
  if (bounds_.size() != audited_.size()) {
    // Once: for a mapper with an explicit operator W >= 0, u = W^T omega (omega: the target's
    // weights, or 1 for a sum) bounds what can arrive: sum_q omega_q |r_q| <= sum_i u_i |s_i|.
    bounds_.assign(audited_.size(), Eigen::VectorXd());
    for (std::size_t i = 0; i < audited_.size(); ++i) {
      const Exchange* e = audited_[i];
      if (!e->mapper()) continue;
      const Eigen::VectorXd omega = e->spec().kind == DataKind::extensive
                                        ? Eigen::VectorXd::Ones(e->target_mesh().size())
                                        : Eigen::VectorXd(e->target_mesh().weights());
      Eigen::VectorXd u;
      if (e->mapper()->arrival_bound(omega, u)) bounds_[i] = std::move(u);
    }
  }
  imbalance_.resize(audited_.size());
  finite_.resize(audited_.size());
  for (std::size_t i = 0; i < audited_.size(); ++i) {
    const Exchange* e = audited_[i];
    const bool extensive = e->spec().kind == DataKind::extensive;
    const Eigen::VectorXd* u = bounds_[i].size() > 0 ? &bounds_[i] : nullptr;
    double ss = 0.0, bound = 0.0, sr = 0.0, unused = 0.0;
    totals(e->sent(), e->source_mesh(), extensive, true, u, sent_, norm_, ss, bound);
    // scale = max(|sent|, |received|) (totals of the magnitudes). Where the bound shows
    // |received| <= |sent| (1 + 1e-6), the received lengths (a square root each) are not
    // summed and the scale is |sent|: low by at most 1e-6 of itself. (The tolerance is above
    // round-off: the cell areas of an STL in float32 and the FE face's quadrature weights
    // differ in their sums by about 2e-8.)
    const bool bounded = u && bound <= ss * (1.0 + 1e-6);
    totals(e->received(), e->target_mesh(), extensive, !bounded, nullptr, received_, norm_, sr,
           unused);
    // A NaN or an infinity among the values makes its total NaN or infinite (weights are finite
    // and >= 0; 0 times an infinity is NaN): finite totals let the health check skip the values.
    finite_[i] = std::isfinite(sent_.sum()) && std::isfinite(received_.sum());
    const double scale = bounded ? ss : std::max(ss, sr);
    imbalance_[i] = scale > 0.0 ? (received_ - sent_).norm() / scale : 0.0;
  }
}

void BalanceAudit::serialize(StateArchive& ar) { ar.io(warnings_); }

void BalanceAudit::report(RunSummary& summary) const {
  summary.imbalance_warnings = static_cast<long>(warnings_);
}

}  // namespace partita::run
