#pragma once
// The interface-work audit of one coupling mesh (Solver::interface_work): the work done on a
// solver, from t = 0, by what it reads on that mesh, integrated with the trapezoidal rule over the
// solver's own steps,
//
//   W += 1/2 (f_k + f_k+1) . (x_k+1 - x_k),
//
// with the copy an implicit scheme's checkpoint keeps and the state a restart file carries. Every
// adapter that reports interface_work() keeps one InterfaceWork per mesh:
//
//   a received motion  (InterfaceWork::motion): the solver places the mesh's points where it is
//                      told; f are the forces its bodies exert on the points, so the motion does
//                      the work -f . dx on them (the DEM's meshes: walls moved by a structure)
//   received loads     (InterfaceWork::loads): the solver reads forces on its nodes and/or
//                      tractions at surface quadrature points, whose work on its own displacement
//                      increments is counted (the FEM's interfaces)
//
// The sums are taken in a fixed order (node by node, the new step's term before the last one's
// where the loads are summed separately), so that a run resumed from a restart file or repeated
// from a checkpoint gives the same bits. No allocation in a step once the arrays have their size.

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace partita {

class BinaryReader;
class BinaryWriter;
class StateArchive;

class InterfaceWork {
 public:
  /// A mesh moved by what the solver reads: the positions x (N x 3) and the forces f (N x 3) of
  /// the solver's bodies on its points at the start.
  static InterfaceWork motion(const Eigen::MatrixX3d& x, const Eigen::MatrixX3d& f);
  /// A mesh on which the solver receives loads (none read yet).
  static InterfaceWork loads();

  /// The work done on the solver through this mesh since t = 0 [J].
  double work() const { return now_.work; }

  /// A received motion: one step, ending with the points at x and the forces f on them:
  /// W -= 1/2 sum_v (f_v,k + f_v,k+1) . (x_v,k+1 - x_v,k), summed point by point.
  void motion_step(const Eigen::MatrixX3d& x, const Eigen::MatrixX3d& f);

  /// Received loads: one step whose displacement increment is `du` (the solver's vector of 3
  /// degrees of freedom a node). `tractions`: the tractions read for this step (nullptr: none
  /// read), whose work on du the solver integrates with its own face rule,
  /// traction_work(t) -> double; `forces`: the nodal forces read for this step (nullptr: none),
  /// row k on node nodes[k]. W += 1/2 (work of this step's loads + work of the last step's, when
  /// the last step had loads of the same size), the tractions' terms first.
  template <class TractionWork>
  void load_step(const Eigen::VectorXd& du, const Eigen::MatrixX3d* tractions,
                 TractionWork&& traction_work, const std::vector<std::size_t>& nodes,
                 const Eigen::MatrixX3d* forces) {
    double w = 0.0;
    if (tractions) {
      w += traction_work(*tractions);
      if (now_.b.rows() == tractions->rows()) w += traction_work(now_.b);
      now_.b = *tractions;
    }
    if (forces) add_nodal_work(w, du, nodes, *forces);
    now_.work += 0.5 * w;
  }

  /// Implicit schemes: keep the state (one slot) and return to it.
  void save_checkpoint() { saved_ = now_; }
  void restore_checkpoint() { now_ = saved_; }

  /// Restart files: the work, then the two arrays of the last step (a motion's positions and
  /// forces; received loads' nodal forces and tractions, empty where none was read), each a
  /// matrix of binary_io.hpp. On loading, a motion's arrays must have its N rows; `what` names
  /// the points in the message (e.g. "vertices of mesh 'lid'").
  void save(BinaryWriter& out) const;
  void load(BinaryReader& in, const std::string& what);

 private:
  enum class Kind { motion, loads };
  // a motion: a = positions, b = forces; loads: a = nodal forces, b = tractions (of the last
  // step; empty until read)
  struct State {
    double work = 0.0;
    Eigen::MatrixX3d a, b;
  };
  explicit InterfaceWork(Kind kind) : kind_(kind) {}
  // save and load, one function for both directions
  void serialize(StateArchive& ar, const std::string& what);
  // load_step's nodal terms, added to w one by one (and the new forces kept)
  void add_nodal_work(double& w, const Eigen::VectorXd& du, const std::vector<std::size_t>& nodes,
                      const Eigen::MatrixX3d& forces);

  Kind kind_;
  State now_, saved_;
};

}  // namespace partita
