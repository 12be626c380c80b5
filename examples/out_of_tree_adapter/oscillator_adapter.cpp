#include "oscillator_adapter.hpp"

#include <cmath>

#include "partita/interface/binary_io.hpp"
#include "partita/interface/error.hpp"

using namespace partita;

OscillatorAdapter::OscillatorAdapter(double mass, double stiffness, State initial)
    : m_(mass), k_(stiffness), s_(initial), checkpoint_(initial) {
  InterfaceMesh m;
  m.mesh = Mesh("mass", Mesh::Points::Zero(1, 3));
  m.writes.push_back(DataSpec{"displacement", 3, "m", DataKind::intensive});
  m.reads.push_back(DataSpec{"force", 3, "N", DataKind::extensive});
  meshes_.push_back(std::move(m));
}

std::shared_ptr<const config::Spec> OscillatorAdapter::spec() {
  auto s = std::make_shared<config::Spec>("oscillator", "a mass on a spring along z");
  s->real("mass", "the mass m").unit("kg").positive().required();
  s->real("stiffness", "the spring stiffness k").unit("N/m").positive().required();
  s->real("displacement", "initial displacement z_0").unit("m").def(0.0);
  s->real("velocity", "initial velocity v_0").unit("m/s").def(0.0);
  return s;
}

std::vector<QuantityDoc> OscillatorAdapter::quantities() {
  return {{"z", "m", "displacement of the mass"},
          {"v", "m/s", "velocity of the mass"},
          {"energy", "J", "kinetic plus spring energy"}};
}

void OscillatorAdapter::register_in(Registry<SolverFactory>& solvers) {
  solvers.add("oscillator", "a mass on a spring along z", create, spec(), quantities());
}

std::unique_ptr<Solver> OscillatorAdapter::create(const SolverContext& context) {
  const config::Node& c = context.config;
  return std::make_unique<OscillatorAdapter>(
      c.real("mass"), c.real("stiffness"),
      State{c.real("displacement"), c.real("velocity"), 0.0});
}

void OscillatorAdapter::read(std::string_view mesh, std::string_view data,
                             const Eigen::MatrixXd& values) {
  if (mesh != "mass" || data != "force")
    throw Error("oscillator reads only 'force' on 'mass', not '" + std::string(data) + "' on '" +
                std::string(mesh) + "'");
  force_ = values(0, 2);
}

void OscillatorAdapter::write(std::string_view mesh, std::string_view data,
                              Eigen::MatrixXd& values) {
  if (mesh != "mass" || data != "displacement")
    throw Error("oscillator writes only 'displacement' on 'mass'");
  values = Eigen::MatrixXd::Zero(1, 3);
  values(0, 2) = s_.z;
}

// Exact for a force constant over the step: about z_eq = F/k the motion is harmonic,
//   z(t + dt) = z_eq + (z - z_eq) cos(w dt) + v/w sin(w dt),  w = sqrt(k/m).
void OscillatorAdapter::advance(double dt) {
  const double w = std::sqrt(k_ / m_), z_eq = force_ / k_;
  const double c = std::cos(w * dt), s = std::sin(w * dt);
  const double z = z_eq + (s_.z - z_eq) * c + s_.v / w * s;
  s_.v = -(s_.z - z_eq) * w * s + s_.v * c;
  s_.z = z;
  s_.t += dt;
}

void OscillatorAdapter::write_restart(BinaryWriter& out) const {
  out.section("oscillator");
  out.write(s_.z);
  out.write(s_.v);
  out.write(s_.t);
  out.write(force_);
}

void OscillatorAdapter::read_restart(BinaryReader& in) {
  in.expect_section("oscillator");
  in.read(s_.z);
  in.read(s_.v);
  in.read(s_.t);
  in.read(force_);
}

std::vector<MonitorValue> OscillatorAdapter::monitors() const {
  return {{"z", "m", s_.z},
          {"v", "m/s", s_.v},
          {"energy", "J", 0.5 * m_ * s_.v * s_.v + 0.5 * k_ * s_.z * s_.z}};
}
