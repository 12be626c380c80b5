#include "partita/tube1d/tube_flow.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

namespace partita::tube1d {

TubeFlow::TubeFlow(TubeParameters parameters) : parameters_(parameters) {
  if (parameters_.cells < 3) throw std::invalid_argument("tube1d: at least 3 cells are needed");
  const int n = parameters_.cells + 1;
  state_.velocity = Eigen::VectorXd::Constant(n, parameters_.initial_velocity);
  state_.pressure = Eigen::VectorXd::Constant(n, parameters_.initial_pressure);
  // the area in equilibrium with the initial pressure (a0 when p = p0)
  const double two_rho_c2 = 2.0 * parameters_.density * parameters_.wave_speed_squared();
  const double q =
      (parameters_.reference_pressure - two_rho_c2) / (parameters_.initial_pressure - two_rho_c2);
  state_.area = Eigen::VectorXd::Constant(n, parameters_.reference_area * q * q);
  next_area_ = state_.area;
}

void TubeFlow::set_area(const Eigen::VectorXd& a) {
  if (a.size() != state_.area.size())
    throw std::invalid_argument("tube1d flow: area has " + std::to_string(a.size()) +
                                " values, expected " + std::to_string(state_.area.size()));
  if ((a.array() <= 0.0).any())
    throw std::runtime_error("tube1d flow: a cross-section area is not positive");
  next_area_ = a;
}

double TubeFlow::face_flux(int i) const {
  const auto& a = state_.area;
  const auto& u = state_.velocity;
  return 0.25 * (a(i) + a(i + 1)) * (u(i) + u(i + 1));
}

void TubeFlow::residual(const Eigen::VectorXd& u, const Eigen::VectorXd& P, double dt, double t_new,
                        Eigen::VectorXd& r) const {
  const int N = parameters_.cells;
  const double dx = parameters_.dx();
  const Eigen::VectorXd& a = next_area_;
  const Eigen::VectorXd& a_old = state_.area;
  const Eigen::VectorXd& u_old = state_.velocity;
  const double c2 = parameters_.wave_speed_squared();
  r.setZero(2 * N + 2);
  for (int i = 1; i < N; ++i) {
    // momentum: (a u)^n - (a u)^{n+1}) dx/dt - [flux of a u^2 and pressure term between faces]
    double m = (u_old(i) * a_old(i) - u(i) * a(i)) * dx / dt;
    m += 0.25 * (-a(i + 1) * u(i) * u(i + 1) - a(i) * u(i) * u(i + 1));
    m += 0.25 * (-a(i + 1) * u(i) * u(i) - a(i) * u(i) * u(i) + a(i) * u(i - 1) * u(i) +
                 a(i - 1) * u(i - 1) * u(i));
    m += 0.25 * (a(i - 1) * u(i - 1) * u(i - 1) + a(i) * u(i - 1) * u(i - 1));
    m += 0.25 * (a(i - 1) * P(i - 1) + a(i) * P(i - 1) - a(i - 1) * P(i) + a(i + 1) * P(i) -
                 a(i) * P(i + 1) - a(i + 1) * P(i + 1));
    r(i) = m;
    // continuity: (a^n - a^{n+1}) dx/dt + F_{i-1/2} - F_{i+1/2} = 0,  F = (a_l + a_r)(u_l + u_r)/4
    r(N + 1 + i) = (a_old(i) - a(i)) * dx / dt + 0.25 * (a(i - 1) + a(i)) * (u(i - 1) + u(i)) -
                   0.25 * (a(i) + a(i + 1)) * (u(i) + u(i + 1));
  }
  r(0) = parameters_.inlet(t_new) - u(0);    // inlet velocity prescribed
  r(N + 1) = -P(0) + 2.0 * P(1) - P(2);      // inlet pressure extrapolated
  r(N) = -u(N) + 2.0 * u(N - 1) - u(N - 2);  // outlet velocity extrapolated
  const double P_old = state_.pressure(N) / parameters_.density;
  const double w = std::sqrt(c2 - P_old / 2.0) - (u(N) - u_old(N)) / 4.0;
  r(2 * N + 1) = -P(N) + 2.0 * (c2 - w * w);  // non-reflecting outlet
}

void TubeFlow::advance(double dt) {
  const int N = parameters_.cells;
  const int n = 2 * N + 2;
  const double t_new = state_.time + dt;
  const double rho = parameters_.density;
  const double dx = parameters_.dx();
  const double c2 = parameters_.wave_speed_squared();
  const Eigen::VectorXd& a = next_area_;
  Eigen::VectorXd u = state_.velocity;
  Eigen::VectorXd P = state_.pressure / rho;
  Eigen::VectorXd r(n);
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(12 * N);
  Eigen::SparseMatrix<double> J(n, n);
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
  bool analysed = false;
  const double scale = std::sqrt(u.squaredNorm() + P.squaredNorm()) + 1.0;
  newton_iterations_ = 0;
  for (int k = 1;; ++k) {
    residual(u, P, dt, t_new, r);
    if (k > 1 && r.norm() <= 1e-13 * scale * (1.0 + dx / dt)) break;
    if (k > 50) {
      char msg[160];
      std::snprintf(msg, sizeof msg,
                    "tube1d flow: Newton did not converge in 50 iterations at t = %g (residual %g)",
                    t_new, r.norm());
      throw std::runtime_error(msg);
    }
    // J = -dR/d(u, P)
    t.clear();
    for (int i = 1; i < N; ++i) {
      const int ip = N + 1 + i;
      t.emplace_back(
          i, i - 1,
          0.25 * (-2 * a(i - 1) * u(i - 1) - 2 * a(i) * u(i - 1) - a(i) * u(i) - a(i - 1) * u(i)));
      t.emplace_back(
          i, i,
          a(i) * dx / dt + 0.25 * (a(i + 1) * u(i + 1) + a(i) * u(i + 1) + 2 * a(i + 1) * u(i) +
                                   2 * a(i) * u(i) - a(i) * u(i - 1) - a(i - 1) * u(i - 1)));
      t.emplace_back(i, i + 1, 0.25 * (a(i + 1) + a(i)) * u(i));
      t.emplace_back(i, ip - 1, -0.25 * (a(i - 1) + a(i)));
      t.emplace_back(i, ip, 0.25 * (a(i - 1) - a(i + 1)));
      t.emplace_back(i, ip + 1, 0.25 * (a(i) + a(i + 1)));
      t.emplace_back(ip, i - 1, -0.25 * (a(i - 1) + a(i)));
      t.emplace_back(ip, i, 0.25 * (a(i + 1) - a(i - 1)));
      t.emplace_back(ip, i + 1, 0.25 * (a(i) + a(i + 1)));
    }
    t.emplace_back(0, 0, 1.0);
    t.emplace_back(N + 1, N + 1, 1.0);
    t.emplace_back(N + 1, N + 2, -2.0);
    t.emplace_back(N + 1, N + 3, 1.0);
    t.emplace_back(N, N, 1.0);
    t.emplace_back(N, N - 1, -2.0);
    t.emplace_back(N, N - 2, 1.0);
    const double P_old = state_.pressure(N) / rho;
    t.emplace_back(2 * N + 1, 2 * N + 1, 1.0);
    t.emplace_back(2 * N + 1, N,
                   -(std::sqrt(c2 - P_old / 2.0) - (u(N) - state_.velocity(N)) / 4.0));
    J.setFromTriplets(t.begin(), t.end());
    if (!analysed) {
      lu.analyzePattern(J);
      analysed = true;
    }
    lu.factorize(J);
    if (lu.info() != Eigen::Success)
      throw std::runtime_error("tube1d flow: singular Newton matrix");
    const Eigen::VectorXd delta = lu.solve(r);
    u += delta.head(N + 1);
    P += delta.tail(N + 1);
    newton_iterations_ = k;
    if (!u.allFinite() || !P.allFinite())
      throw std::runtime_error("tube1d flow: the Newton iteration diverged at t = " +
                               std::to_string(t_new));
    if (delta.norm() <= 1e-11 * scale) {
      residual(u, P, dt, t_new, r);
      break;
    }
  }
  state_.velocity = u;
  state_.pressure = P * rho;
  state_.area = next_area_;
  state_.time = t_new;
}

}  // namespace partita::tube1d
