#pragma once
// Test-local participants with exact energy books: a damped mass on a spring (test-mass) pushed
// by a constant applied force, coupled at one point to a massless spring (test-spring) that
// pulls it back: the mass writes its displacement x and reads the spring's force; the spring
// reads x and writes -k_b x.
//
// The mass steps with the implicit midpoint rule, which keeps the books of a linear oscillator
// exactly: over a step, with v_m = (v0 + v1) / 2 and dx = dt v_m,
//   d(1/2 m v^2 + 1/2 k x^2) = (f + u) dx - c v_m^2 dt
// (f: the applied force, u: the force read, held over the step). So its monitors applied_work
// = sum f dx, damping_work = sum c v_m^2 dt and interface_work = sum u dx close its own balance to
// round-off, and any imbalance of the coupled system is the coupling's.

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "partita/coupling/registries.hpp"
#include "partita/interface/binary_io.hpp"
#include "partita/interface/solver.hpp"

namespace partita::coupling::test {

// With driver_speed s != 0 it also has a mesh "driver" whose displacement is s t, prescribed
// (InterfaceMesh::prescribed as driver_prescribed says): a driven body beside the mass.
class MassParticipant : public Solver {
 public:
  MassParticipant(double m, double k, double c, double f, double x0, double v0,
                  double driver_speed = 0.0, bool driver_prescribed = true)
      : m_(m), k_(k), c_(c), f_(f), x_(x0), v_(v0), driver_speed_(driver_speed) {
    InterfaceMesh im;
    im.mesh = Mesh("point", Mesh::Points::Zero(1, 3));
    im.writes.push_back(DataSpec{"displacement", 1, "m", DataKind::intensive});
    im.reads.push_back(DataSpec{"force", 1, "N", DataKind::extensive});
    meshes_.push_back(std::move(im));
    if (driver_speed != 0.0) {
      InterfaceMesh driver;
      driver.mesh = Mesh("driver", Mesh::Points::Zero(1, 3));
      driver.writes.push_back(DataSpec{"displacement", 1, "m", DataKind::intensive});
      driver.prescribed = driver_prescribed;
      meshes_.push_back(std::move(driver));
    }
  }
  const std::vector<InterfaceMesh>& meshes() const override { return meshes_; }
  void read(std::string_view, std::string_view, const Eigen::MatrixXd& v) override {
    u_ = v(0, 0);
  }
  void write(std::string_view mesh, std::string_view, Eigen::MatrixXd& v) override {
    v.resize(1, 1);
    v(0, 0) = mesh == "driver" ? driver_speed_ * t_ : x_;
  }
  double stable_time_step() const override { return INFINITY; }
  void advance(double dt) override {
    const double a = dt / m_ * (0.25 * k_ * dt + 0.5 * c_);
    const double v1 = ((1.0 - a) * v_ + dt / m_ * (f_ + u_ - k_ * x_)) / (1.0 + a);
    const double vm = 0.5 * (v_ + v1);
    const double dx = dt * vm;
    s_.applied += f_ * dx;
    s_.work += u_ * dx;
    s_.damping += c_ * vm * vm * dt;
    x_ += dx;
    v_ = v1;
    t_ += dt;
  }
  double time() const override { return t_; }
  void save_checkpoint() override { saved_ = {x_, v_, t_, u_, s_}; }
  void restore_checkpoint() override {
    x_ = saved_.x;
    v_ = saved_.v;
    t_ = saved_.t;
    u_ = saved_.u;
    s_ = saved_.s;
  }
  std::vector<MonitorValue> monitors() const override {
    return {{"kinetic_energy", "J", 0.5 * m_ * v_ * v_},
            {"elastic_energy", "J", 0.5 * k_ * x_ * x_},
            {"applied_work", "J", s_.applied},
            {"damping_work", "J", s_.damping},
            {"x", "m", x_}};
  }
  std::optional<double> interface_work(std::string_view mesh) const override {
    if (mesh != "point") return std::nullopt;
    return s_.work;
  }
  bool supports_restart() const override { return true; }
  void write_restart(BinaryWriter& out) const override {
    for (const double v : {x_, v_, t_, u_, s_.applied, s_.work, s_.damping}) out.write(v);
  }
  void read_restart(BinaryReader& in) override {
    for (double* v : {&x_, &v_, &t_, &u_, &s_.applied, &s_.work, &s_.damping}) in.read(*v);
  }

 private:
  struct Sums {
    double applied = 0.0, work = 0.0, damping = 0.0;
  };
  struct Saved {
    double x = 0.0, v = 0.0, t = 0.0, u = 0.0;
    Sums s;
  };
  std::vector<InterfaceMesh> meshes_;
  double m_, k_, c_, f_, x_, v_, driver_speed_, u_ = 0.0, t_ = 0.0;
  Sums s_;
  Saved saved_;
};

// With probe_stiffness k_p > 0 it has a second mesh "probe" that only reads a displacement: a
// spring k_p to the ground driven by it, which pushes nothing back (a driven body's surface);
// its interface_work is the driving motion's work on it, 1/2 k_p x_p^2.
class SpringParticipant : public Solver {
 public:
  explicit SpringParticipant(double k, double k_probe = 0.0) : k_(k), kp_(k_probe) {
    InterfaceMesh im;
    im.mesh = Mesh("point", Mesh::Points::Zero(1, 3));
    im.writes.push_back(DataSpec{"force", 1, "N", DataKind::extensive});
    im.reads.push_back(DataSpec{"displacement", 1, "m", DataKind::intensive});
    meshes_.push_back(std::move(im));
    if (kp_ > 0.0) {
      InterfaceMesh probe;
      probe.mesh = Mesh("probe", Mesh::Points::Zero(1, 3));
      probe.reads.push_back(DataSpec{"displacement", 1, "m", DataKind::intensive});
      meshes_.push_back(std::move(probe));
    }
  }
  const std::vector<InterfaceMesh>& meshes() const override { return meshes_; }
  void read(std::string_view mesh, std::string_view, const Eigen::MatrixXd& v) override {
    (mesh == "probe" ? probe_next_ : next_) = v(0, 0);
  }
  void write(std::string_view, std::string_view, Eigen::MatrixXd& v) override {
    v.resize(1, 1);
    v(0, 0) = -k_ * x_;
  }
  double stable_time_step() const override { return INFINITY; }
  // massless: it follows the displacement read; the boundary's work on it, k x dx, summed with
  // the trapezoidal rule (exact for the linear force), is its elastic energy
  void advance(double dt) override {
    work_ += 0.5 * k_ * (x_ + next_) * (next_ - x_);
    x_ = next_;
    probe_work_ += 0.5 * kp_ * (probe_ + probe_next_) * (probe_next_ - probe_);
    probe_ = probe_next_;
    t_ += dt;
  }
  double time() const override { return t_; }
  void save_checkpoint() override { saved_ = {x_, next_, t_, work_}; }
  void restore_checkpoint() override {
    x_ = saved_[0];
    next_ = saved_[1];
    t_ = saved_[2];
    work_ = saved_[3];
  }
  std::vector<MonitorValue> monitors() const override {
    return {{"elastic_energy", "J", 0.5 * k_ * x_ * x_}};
  }
  std::optional<double> interface_work(std::string_view mesh) const override {
    if (mesh == "probe" && kp_ > 0.0) return probe_work_;
    if (mesh != "point") return std::nullopt;
    return work_;
  }
  bool supports_restart() const override { return true; }
  void write_restart(BinaryWriter& out) const override {
    for (const double v : {x_, next_, t_, work_}) out.write(v);
  }
  void read_restart(BinaryReader& in) override {
    for (double* v : {&x_, &next_, &t_, &work_}) in.read(*v);
  }

 private:
  std::vector<InterfaceMesh> meshes_;
  double k_, kp_, x_ = 0.0, next_ = 0.0, t_ = 0.0, work_ = 0.0;
  double probe_ = 0.0, probe_next_ = 0.0, probe_work_ = 0.0;  // not saved: the audit's test only
  std::vector<double> saved_ = {0, 0, 0, 0};
};

/// Adds "test-mass" (keys mass, stiffness, damping, force, x0, v0) and "test-spring" (stiffness).
inline void add_oscillator_solvers(Registries& r) {
  auto mass = std::make_shared<config::Spec>("test-mass", "a damped mass on a spring");
  mass->real("mass", "mass").positive().def(1.0);
  mass->real("stiffness", "its spring to the ground").positive().def(100.0);
  mass->real("damping", "viscous damping").min(0.0).def(0.0);
  mass->real("force", "constant applied force").def(0.0);
  mass->real("x0", "initial displacement").def(0.0);
  mass->real("v0", "initial velocity").def(0.0);
  mass->real("driver_speed", "speed of the mesh driver (0: no such mesh)").def(0.0);
  mass->boolean("driver_prescribed", "the mesh driver is marked prescribed").def(true);
  r.solvers.add(
      "test-mass", "a damped mass on a spring",
      [](const SolverContext& c) -> std::unique_ptr<Solver> {
        return std::make_unique<MassParticipant>(c.config.real("mass"), c.config.real("stiffness"),
                                                 c.config.real("damping"), c.config.real("force"),
                                                 c.config.real("x0"), c.config.real("v0"),
                                                 c.config.real("driver_speed"),
                                                 c.config.boolean("driver_prescribed"));
      },
      mass);
  auto spring = std::make_shared<config::Spec>("test-spring", "a massless spring");
  spring->real("stiffness", "stiffness").positive().def(100.0);
  spring->real("probe_stiffness", "a second, driven spring on the mesh probe (0: none)").min(0.0).def(0.0);
  r.solvers.add(
      "test-spring", "a massless spring",
      [](const SolverContext& c) -> std::unique_ptr<Solver> {
        return std::make_unique<SpringParticipant>(c.config.real("stiffness"),
                                                   c.config.real("probe_stiffness"));
      },
      spring);
}

}  // namespace partita::coupling::test
