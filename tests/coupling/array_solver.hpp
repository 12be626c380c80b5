#pragma once
// A test solver: one mesh of n points that writes and reads "f" (3 components); write() gives
// `next` (or the next of `script`), with a NaN from time `nan_from` on.
#include <cmath>
#include <limits>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "partita/interface/solver.hpp"

namespace partita::coupling::test {

class ArraySolver : public Solver {
 public:
  ArraySolver(Eigen::Index n, DataKind kind, double nan_from = INFINITY, double weight = 0.0)
      : nan_from_(nan_from) {
    InterfaceMesh m;
    m.mesh = Mesh("points", Mesh::Points::Random(n, 3));
    if (weight > 0.0) m.mesh.set_weights(Eigen::VectorXd::Constant(n, weight));
    m.writes.push_back(DataSpec{"f", 3, "N", kind});
    m.reads.push_back(DataSpec{"f", 3, "N", kind});
    meshes_.push_back(std::move(m));
    next.setOnes(n, 3);
  }
  const std::vector<InterfaceMesh>& meshes() const override { return meshes_; }
  void read(std::string_view, std::string_view, const Eigen::MatrixXd& v) override {
    seen = v;
    if (log_reads) reads.push_back(v);
  }
  void write(std::string_view, std::string_view, Eigen::MatrixXd& v) override {
    v = script.empty() ? next : script[written++ % script.size()];
    if (t_ >= nan_from_) v(v.rows() / 2, 1) = std::numeric_limits<double>::quiet_NaN();
  }
  double stable_time_step() const override { return INFINITY; }
  void advance(double dt) override { t_ += dt; }
  double time() const override { return t_; }
  void save_checkpoint() override {}
  void restore_checkpoint() override {}

  Eigen::MatrixXd next, seen;
  std::vector<Eigen::MatrixXd> script;  // written in turn, one a write() (empty: `next`)
  std::size_t written = 0;
  bool log_reads = false;
  std::vector<Eigen::MatrixXd> reads;

 private:
  std::vector<InterfaceMesh> meshes_;
  double t_ = 0.0, nan_from_;
};

}  // namespace partita::coupling::test
