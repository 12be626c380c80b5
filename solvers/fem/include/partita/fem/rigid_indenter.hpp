#pragma once
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "partita/fem/rigid_shape.hpp"
#include "partita/fem/velocity_table.hpp"

namespace partita::fem {

// A rigid body that translates (no rotation): a RigidShape at displacement d(t) from its initial
// position. Either driven (d(t) = int_0^t v ds of a VelocityTable) or free (mass m, initial
// velocity, gravity g), integrated with the structure's central-difference step in
// velocity-Verlet form, the same as the nodes (CentralDifferenceIntegrator):
//   V_1/2 = V + dt/2 A,  d_1 = d + dt V_1/2,  F_1 = contact force at (u_1, d_1),
//   A_1 = F_1 / m + g,  V_1 = V_1/2 + dt/2 A_1,
// so that the contact forces on the nodes and on the body act at the same instants and the
// momentum of body + structure changes only by the external impulses (gravity, supports).
//
// Call order (IndenterContact does it): move_to(t) places the trial configuration at t from
// the committed one (any number of times: Newton iterations, cut-backs); set_contact_force(F)
// after each evaluation at the trial configuration; commit(work) when the step is accepted,
// with the work the body did on the structure over the step (IndenterContact integrates it node
// by node; without it, the trapezoid -1/2 (F_n + F_n+1) . (d_n+1 - d_n), F the force on the
// body); the first contact and the penetration are committed with it.
//
// An external force (set_external_force: e.g. the granules' push on a bow that has broken into a
// filled cell, handed over by the coupling once a window) acts on a free body beside the contact
// force, A = (F + F_ext) / m + g, held until it is set again; its work on the body,
// sum F_ext . (d_n+1 - d_n) (exact for a force held over the step), is committed too. A driven
// body's motion ignores it (its work is still booked: what the prescribed motion did against it).
class RigidIndenter {
 public:
  RigidIndenter(std::shared_ptr<const RigidShape> shape, VelocityTable velocity);
  // Throws Error unless mass > 0 and the vectors finite.
  RigidIndenter(std::shared_ptr<const RigidShape> shape, double mass, const Vec3& velocity,
                const Vec3& gravity);

  const RigidShape& shape() const { return *shape_; }
  bool is_free() const { return !table_.has_value(); }
  double mass() const { return mass_; }

  void move_to(double t);
  void set_contact_force(const Vec3& force);
  // From the next move_to on (throws Error unless finite).
  void set_external_force(const Vec3& force);
  void commit();
  void commit(double work_increment);

  // trial configuration (of the last move_to)
  const Vec3& trial_displacement() const { return trial_.d; }
  double trial_time() const { return trial_.t; }
  // committed configuration
  double time() const { return committed_.t; }
  const Vec3& displacement() const { return committed_.d; }
  const Vec3& velocity() const { return committed_.v; }
  const Vec3& contact_force() const { return committed_.f; }  // on the body [N]
  double work() const { return committed_.work; }  // done on the structure [J]
  const Vec3& external_force() const { return external_; }  // on the body [N]
  double external_work() const { return committed_.external_work; }  // done on the body [J]
  double kinetic_energy() const { return is_free() ? 0.5 * mass_ * committed_.v.squaredNorm() : 0.0; }
  // Displacement along the path since the first contact: (d - d_c) . e, d_c the displacement at
  // the first committed step with a contact force, e the direction of motion then (0 before).
  double penetration() const;

  // The committed state, flattened (restart), and its restoration (the trial becomes it).
  static constexpr std::size_t kStateSize = 23;
  void write_state(std::span<double> out) const;
  void read_state(std::span<const double> in);

 private:
  struct Configuration {
    double t = 0.0;
    Vec3 d = Vec3::Zero(), v = Vec3::Zero(), f = Vec3::Zero();
    double work = 0.0;
    double external_work = 0.0;
    bool touched = false;  // a contact force has acted
    Vec3 d_first = Vec3::Zero(), e_first = Vec3::Zero();
  };
  std::shared_ptr<const RigidShape> shape_;
  std::optional<VelocityTable> table_;
  double mass_ = 0.0;
  Vec3 gravity_ = Vec3::Zero();
  Vec3 external_ = Vec3::Zero();
  Configuration committed_, trial_;
};

}  // namespace partita::fem
