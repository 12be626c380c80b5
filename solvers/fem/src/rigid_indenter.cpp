#include "partita/fem/rigid_indenter.hpp"

#include <cmath>
#include <string>

#include "partita/fem/error.hpp"

namespace partita::fem {

RigidIndenter::RigidIndenter(std::shared_ptr<const RigidShape> shape, VelocityTable velocity)
    : shape_(std::move(shape)), table_(std::move(velocity)) {
  if (!shape_) throw Error("rigid indenter: no shape");
  committed_.v = table_->velocity(0.0);
  trial_ = committed_;
}

RigidIndenter::RigidIndenter(std::shared_ptr<const RigidShape> shape, double mass,
                             const Vec3& velocity, const Vec3& gravity)
    : shape_(std::move(shape)), mass_(mass), gravity_(gravity) {
  if (!shape_) throw Error("rigid indenter: no shape");
  if (!(mass > 0.0) || !std::isfinite(mass))
    throw Error("rigid indenter: the mass must be > 0, got " + std::to_string(mass));
  if (!velocity.allFinite() || !gravity.allFinite())
    throw Error("rigid indenter: the velocity and gravity must be finite");
  committed_.v = velocity;
  trial_ = committed_;
}

void RigidIndenter::move_to(double t) {
  trial_ = committed_;
  trial_.t = t;
  const double dt = t - committed_.t;
  if (dt == 0.0) return;
  if (table_) {
    trial_.d = table_->displacement(t);
    trial_.v = table_->velocity(t);
    return;
  }
  // V_1/2 = V + dt/2 A;  d_1 = d + dt V_1/2  (V_1 follows from the force at d_1 in commit())
  const Vec3 v_half = committed_.v + 0.5 * dt * ((committed_.f + external_) / mass_ + gravity_);
  trial_.d = committed_.d + dt * v_half;
  trial_.v = v_half;
}

void RigidIndenter::set_contact_force(const Vec3& force) {
  trial_.f = force;
  // at the committed configuration (the start of a run, a restored state): the force belongs
  // to it, and the next step's acceleration is taken from it
  if (trial_.t == committed_.t && trial_.d == committed_.d) committed_.f = force;
}

void RigidIndenter::set_external_force(const Vec3& force) {
  if (!force.allFinite()) throw Error("rigid indenter: the external force must be finite");
  external_ = force;
}

void RigidIndenter::commit() {
  // W += -1/2 (F_n + F_n+1) . (d_n+1 - d_n)
  commit(-0.5 * (committed_.f + trial_.f).dot(trial_.d - committed_.d));
}

void RigidIndenter::commit(double work_increment) {
  const double dt = trial_.t - committed_.t;
  if (!table_ && dt != 0.0) {
    // A_1 = F_1 / m + g;  V_1 = V_1/2 + dt/2 A_1
    trial_.v += 0.5 * dt * ((trial_.f + external_) / mass_ + gravity_);
  }
  trial_.external_work = committed_.external_work + external_.dot(trial_.d - committed_.d);
  trial_.work = committed_.work + work_increment;
  if (!committed_.touched && trial_.f.squaredNorm() > 0.0) {
    trial_.touched = true;
    trial_.d_first = committed_.d;
    Vec3 e = trial_.d - committed_.d;
    if (!(e.norm() > 0.0)) e = -trial_.f;  // at rest: into the structure
    trial_.e_first = e.normalized();
  }
  committed_ = trial_;
}

double RigidIndenter::penetration() const {
  return committed_.touched ? (committed_.d - committed_.d_first).dot(committed_.e_first) : 0.0;
}

void RigidIndenter::write_state(std::span<double> out) const {
  const Configuration& c = committed_;
  double* p = out.data();
  *p++ = c.t;
  for (const Vec3* v : {&c.d, &c.v, &c.f, &c.d_first, &c.e_first, &external_})
    for (int k = 0; k < 3; ++k) *p++ = (*v)[k];
  *p++ = c.work;
  *p++ = c.external_work;
  *p++ = c.touched ? 1.0 : 0.0;
  (void)p;
}

void RigidIndenter::read_state(std::span<const double> in) {
  if (in.size() != kStateSize)
    throw Error("rigid indenter: a state of " + std::to_string(in.size()) + " values, expected " +
                std::to_string(kStateSize));
  Configuration& c = committed_;
  const double* p = in.data();
  c.t = *p++;
  for (Vec3* v : {&c.d, &c.v, &c.f, &c.d_first, &c.e_first, &external_})
    for (int k = 0; k < 3; ++k) (*v)[k] = *p++;
  c.work = *p++;
  c.external_work = *p++;
  c.touched = *p++ != 0.0;
  trial_ = committed_;
}

}  // namespace partita::fem
