#pragma once
// The tube wall: the tube law relating the cross-section area at each node to the pressure,
//   a(p) = a0 ((p0 - 2 rho c^2) / (p - 2 rho c^2))^2,    c^2 = E / (2 rho r0),
// whose inverse p(a) = 2 rho c^2 - (2 rho c^2 - p0) sqrt(a0 / a) has dp/da = rho c^2 / a0 at a0
// (c is the Moens-Korteweg wave speed). No inertia: the wall is in equilibrium at every step.
//
// Call order: set_pressure(p) for the new time; advance(dt) computes the areas; area().

#include <Eigen/Core>

#include "partita/tube1d/tube_parameters.hpp"

namespace partita::tube1d {

class TubeWall {
 public:
  explicit TubeWall(TubeParameters parameters);

  const TubeParameters& parameters() const { return parameters_; }
  /// Pressure at the N + 1 nodes [Pa].
  void set_pressure(const Eigen::VectorXd& p);
  /// a = a(p) at every node.
  void advance(double dt);
  const Eigen::VectorXd& area() const { return area_; }
  const Eigen::VectorXd& pressure() const { return pressure_; }
  double time() const { return time_; }
  void set_time(double t) { time_ = t; }
  /// The whole state at once (restart files): pressure and area at the nodes, time.
  void set_state(const Eigen::VectorXd& pressure, const Eigen::VectorXd& area, double time);

  /// The tube law a(p) and its inverse p(a).
  double area_of(double p) const;
  double pressure_of(double a) const;

 private:
  TubeParameters parameters_;
  Eigen::VectorXd pressure_, area_;
  double time_ = 0.0;
};

}  // namespace partita::tube1d
