#include "partita/coupling/mapping/sparse_mapper.hpp"

#include "partita/interface/error.hpp"

namespace partita::coupling {

void SparseMapper::compute(const Mesh& from, const Mesh& to) {
  if (from.size() == 0 || to.size() == 0)
    throw Error("mapper '" + name() + "' from mesh '" + from.name() + "' to mesh '" + to.name() +
                "': mesh '" + (from.size() == 0 ? from.name() : to.name()) + "' has no points");
  if (constraint_ == Constraint::consistent) {
    matrix_ = interpolation(from, to);  // |to| x |from|
  } else {
    // W_AB^T: the transpose of the consistent interpolation from `to` back to `from`.
    matrix_ = Matrix(interpolation(to, from).transpose());
  }
  matrix_.makeCompressed();
  set_meshes(from, to);
}

void SparseMapper::map(const Eigen::MatrixXd& in, Eigen::MatrixXd& out) const {
  check_input(in);
  // out = W in  (W = matrix_, |to| x |from|; consistent or the transposed conservative one)
  out.resize(matrix_.rows(), in.cols());
  out.noalias() = matrix_ * in;
}

}  // namespace partita::coupling
