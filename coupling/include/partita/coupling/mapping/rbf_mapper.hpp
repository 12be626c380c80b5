#pragma once
// rbf: radial basis function interpolation with a linear polynomial.
//
//   s(x) = sum_j alpha_j phi(|x - x_j|) + p(x),   p(x) = c_0 + sum_k c_k xi_k(x),
//
// centres x_j = the points of the mesh the values live on (the source of a consistent mapping,
// the target of a conservative one, whose operator is the transpose). Bases:
//   wendland-c2        phi(r) = (1 - r/R)^4 (4 r/R + 1) for r < R, else 0 (compact support R:
//                      sparse system, sparse factorisation; the default)
//   gaussian           phi(r) = exp(-(r/R)^2), global, dense (small meshes only)
//   thin-plate-spline  phi(r) = r^2 log r, global, dense (small meshes only; needs the
//                      polynomial)
// Polynomial (the xi_k are the principal directions of the centres that have extent, so a flat
// plate gets no term normal to it and a straight line only one):
//   separate (default) p fitted first by least squares, the RBF interpolates the residual:
//                      Phi alpha = f - P c; Phi is symmetric positive definite (Cholesky LDL^T)
//   on                 the saddle-point system [Phi P; P^T 0] [alpha; c] = [f; 0], solved
//                      through its q x q Schur complement P^T Phi^-1 P (sparse Cholesky of Phi)
//   off                no polynomial: constants are not reproduced, so not allowed for a
//                      conservative mapping (the total would not be preserved)
// Solver of the compact system (option `solver`): cholesky (default) or cg (preconditioned
// conjugate gradients to `tolerance`, for large meshes; a conservative mapping then keeps the
// total exactly with polynomial: separate, to the tolerance with polynomial: on).
// Unlike the sparse-matrix mappers, the operator E K^-1 is dense; compute() factorises K and
// map() does one solve and one sparse product (with temporaries of the mesh size).
// Global bases factorise densely (Phi, or the whole saddle-point system: thin-plate splines
// are only conditionally positive definite).

#include <memory>

#include <Eigen/Core>

#include "partita/coupling/mapping/mapper.hpp"

namespace partita::coupling {

class RbfMapper final : public Mapper {
 public:
  enum class Basis { wendland_c2, gaussian, thin_plate_spline };
  enum class Polynomial { separate, on, off };
  /// How the compact system Phi is solved: a sparse Cholesky factorisation (LDL^T, AMD
  /// ordering; exact, but its fill grows faster than n on a surface), or conjugate gradients
  /// preconditioned with an incomplete Cholesky factor (each map() iterates to `tolerance`).
  /// automatic: cholesky up to automatic_cg_threshold centres, cg above (keeps large meshes
  /// near n log n; the sparse factorisation of a surface grows like n^1.5 or more).
  enum class Solver { cholesky, cg, automatic };
  static constexpr Eigen::Index automatic_cg_threshold = 20000;

  /// `support_radius` [m]: R of wendland-c2 and gaussian (ignored by thin-plate-spline).
  /// Throws partita::Error for an invalid combination (radius <= 0, conservative without
  /// polynomial, thin-plate-spline without polynomial).
  RbfMapper(Constraint constraint, Basis basis, double support_radius,
            Polynomial polynomial = Polynomial::separate, Solver solver = Solver::cholesky,
            double tolerance = 1e-10);
  ~RbfMapper() override;

  void compute(const Mesh& from, const Mesh& to) override;
  void map(const Eigen::MatrixXd& in, Eigen::MatrixXd& out) const override;
  Constraint constraint() const override { return constraint_; }
  std::string name() const override { return "rbf"; }

  /// Number of polynomial terms in use after compute() (1 + the dimensions with extent).
  int polynomial_terms() const;

  /// Global (dense) bases refuse meshes larger than this.
  static constexpr Eigen::Index max_dense_points = 4000;

  static std::shared_ptr<const config::Spec> spec();
  static std::unique_ptr<Mapper> create(const MapperContext& context);

 private:
  struct System;

  Constraint constraint_;
  Basis basis_;
  double radius_;
  Polynomial polynomial_;
  Solver solver_;
  double tolerance_;
  std::unique_ptr<System> system_;
};

}  // namespace partita::coupling
