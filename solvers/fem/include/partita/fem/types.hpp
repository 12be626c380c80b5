#pragma once
#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <functional>

namespace partita::fem {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
// Voigt vectors are ordered xx, yy, zz, xy, yz, zx; strains carry engineering shears.
using Voigt = Eigen::Matrix<double, 6, 1>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;
// Fourth-order tensors acting on 3x3 tensors, flattened row-major: A(3 i + J, 3 k + L).
using Matrix9 = Eigen::Matrix<double, 9, 9>;
// N x 3 arrays (one row per point / node), row-major so that a row is contiguous.
using MatrixX3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
// N x 6 arrays of Voigt stresses.
using MatrixX6 = Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>;
using SparseMatrix = Eigen::SparseMatrix<double>;

// Load amplitudes and prescribed values as functions of time t [s].
using TimeFunction = std::function<double(double t)>;
// Prescribed values as functions of the reference position x [m] and time t [s].
using SpaceTimeFunction = std::function<double(const Vec3& x, double t)>;

// Largest element: Hex20, 20 nodes, 60 dofs. Largest face: Quad8.
inline constexpr int kMaxElementNodes = 20;
inline constexpr int kMaxElementDofs = 60;
inline constexpr int kMaxFaceNodes = 8;

}  // namespace partita::fem
