#pragma once
#include <cstddef>
#include <vector>

namespace partita::fem {

// The consistent nodal forces of tractions given at a face's quadrature points:
//   f[node[k]] += coefficient[k] t[qp[k]]   for every k,   coefficient = N_a(x_q) w_q,
// one entry per (surface element node, quadrature point) in face_quadrature_points() order
// (StructuralSolver builds one per face on first use; its transpose gives the tractions' work).
struct FaceLoadOperator {
  std::vector<std::size_t> node;
  std::vector<std::size_t> qp;
  std::vector<double> coefficient;
  std::size_t num_qp = 0;  // quadrature points of the face
};

}  // namespace partita::fem
