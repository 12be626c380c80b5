#pragma once
// Test-local participants: one scalar of a linear ODE system each,
//   y1' = -a1 y1 + b1 y2,   y2' = -a2 y2 + b2 y1,
// split so that participant 1 owns y1 and reads y2, participant 2 the reverse. Each advances its
// own scalar exactly for an input held constant over the step:
//   y(t + dt) = e^{-a dt} y(t) + (b/a) (1 - e^{-a dt}) u.
// So the only error of a coupled run is the coupling's.

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "partita/coupling/registries.hpp"
#include "partita/interface/solver.hpp"

namespace partita::coupling::test {

class OdeParticipant : public Solver {
 public:
  OdeParticipant(std::string writes, std::string reads, double a, double b, double y0,
                 double stable_dt = INFINITY)
      : a_(a), b_(b), y_(y0), stable_(stable_dt) {
    InterfaceMesh m;
    m.mesh = Mesh("point", Mesh::Points::Zero(1, 3));
    m.writes.push_back(DataSpec{writes, 1, "m", DataKind::intensive});
    m.reads.push_back(DataSpec{reads, 1, "m", DataKind::intensive});
    meshes_.push_back(std::move(m));
  }
  const std::vector<InterfaceMesh>& meshes() const override { return meshes_; }
  void read(std::string_view, std::string_view, const Eigen::MatrixXd& v) override {
    u_ = v(0, 0);
    reads_.push_back(u_);
  }
  void write(std::string_view, std::string_view, Eigen::MatrixXd& v) override {
    v.resize(1, 1);
    v(0, 0) = output_ ? output_(t_) : y_;
  }
  double stable_time_step() const override { return stable_; }
  void advance(double dt) override {
    const double e = std::exp(-a_ * dt);
    y_ = e * y_ + (b_ / a_) * (1.0 - e) * u_;
    t_ += dt;
    steps_.push_back(dt);
  }
  double time() const override { return t_; }
  void save_checkpoint() override { saved_ = {y_, t_, u_}; }
  void restore_checkpoint() override {
    y_ = saved_[0];
    t_ = saved_[1];
    u_ = saved_[2];
  }
  std::vector<MonitorValue> monitors() const override { return {{"y", "m", y_}}; }

  double y() const { return y_; }
  double input() const { return u_; }
  /// Every value read, in order, and every step taken.
  std::vector<double> reads_, steps_;
  /// If set, write() returns output_(time) instead of y.
  std::function<double(double)> output_;

 private:
  std::vector<InterfaceMesh> meshes_;
  double a_, b_, y_, u_ = 0.0, t_ = 0.0, stable_;
  std::vector<double> saved_ = {0, 0, 0};
};

/// Registries with the built-ins and the solver "test-ode" (keys a, b, y0, writes, reads,
/// stable_dt).
inline Registries test_registries() {
  Registries r;
  register_builtin(r);
  auto spec = std::make_shared<config::Spec>("test-ode", "one scalar of a linear ODE system");
  spec->real("a", "decay rate").positive().def(1.0);
  spec->real("b", "coupling coefficient").def(0.5);
  spec->real("y0", "initial value").def(0.0);
  spec->string("writes", "name of the written field").required();
  spec->string("reads", "name of the read field").required();
  spec->real("stable_dt", "stable time step").positive().def(1e300);
  r.solvers.add(
      "test-ode", "scalar linear ODE",
      [](const SolverContext& c) -> std::unique_ptr<Solver> {
        return std::make_unique<OdeParticipant>(c.config.string("writes"), c.config.string("reads"),
                                                c.config.real("a"), c.config.real("b"),
                                                c.config.real("y0"), c.config.real("stable_dt"));
      },
      spec);
  return r;
}

}  // namespace partita::coupling::test
