#include "oscillator_adapter.hpp"

#include <cmath>

#include "partita/interface/binary_io.hpp"
#include "partita/interface/error.hpp"

using namespace partita;

OscillatorAdapter::OscillatorAdapter(double mass, double stiffness, State initial, double gravity,
                                     double damping)
    : m_(mass), k_(stiffness), g_(gravity), c_(damping), s_(initial), checkpoint_(initial) {
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
  s->real("gravity", "gravitational acceleration g along z (the weight m g; e.g. -9.81)")
      .unit("m/s^2")
      .def(0.0);
  s->real("damping", "dashpot coefficient c between the mass and the fixed support (force -c v)")
      .unit("N s/m")
      .non_negative()
      .def(0.0);
  return s;
}

std::vector<QuantityDoc> OscillatorAdapter::quantities() {
  return {{"z", "m", "displacement of the mass"},
          {"v", "m/s", "velocity of the mass"},
          {"energy", "J", "kinetic plus spring energy (plus the weight's potential energy -m g z)"}};
}

void OscillatorAdapter::register_in(Registry<SolverFactory>& solvers) {
  solvers.add("oscillator", "a mass on a spring along z", create, spec(), quantities());
}

std::unique_ptr<Solver> OscillatorAdapter::create(const SolverContext& context) {
  const config::Node& c = context.config;
  return std::make_unique<OscillatorAdapter>(
      c.real("mass"), c.real("stiffness"),
      State{c.real("displacement"), c.real("velocity"), 0.0}, c.real("gravity"), c.real("damping"));
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

// Exact for a force constant over the step (the force read plus the weight m g): about
// z_eq = (F + m g)/k the motion y = z - z_eq is that of a free damped oscillator,
//   m y'' + c y' + k y = 0,  w0 = sqrt(k/m),  h = c/(2m):
//   y(t + dt) = e^(-h dt) (y C + (v + h y) S),  v(t + dt) = e^(-h dt) (v C - (w0^2 y + h v) S)
// with C = cos(wd dt), S = sin(wd dt)/wd, wd = sqrt(w0^2 - h^2) (underdamped; undamped: h = 0),
// C = cosh(q dt), S = sinh(q dt)/q, q = sqrt(h^2 - w0^2) (overdamped), C = 1, S = dt (critical).
void OscillatorAdapter::advance(double dt) {
  const double w0 = std::sqrt(k_ / m_), z_eq = (force_ + m_ * g_) / k_;
  const double h = c_ / (2.0 * m_), d = w0 * w0 - h * h;
  double C = 1.0, S = dt;
  if (d > 0.0) {
    const double wd = std::sqrt(d);
    C = std::cos(wd * dt);
    S = std::sin(wd * dt) / wd;
  } else if (d < 0.0) {
    const double q = std::sqrt(-d);
    C = std::cosh(q * dt);
    S = std::sinh(q * dt) / q;
  }
  const double decay = std::exp(-h * dt), y = s_.z - z_eq;
  s_.z = z_eq + decay * (y * C + (s_.v + h * y) * S);
  s_.v = decay * (s_.v * C - (w0 * w0 * y + h * s_.v) * S);
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
          {"energy", "J", 0.5 * m_ * s_.v * s_.v + 0.5 * k_ * s_.z * s_.z - m_ * g_ * s_.z}};
}
