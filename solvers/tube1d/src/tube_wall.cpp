#include "partita/tube1d/tube_wall.hpp"

#include <cmath>
#include <stdexcept>

namespace partita::tube1d {

TubeWall::TubeWall(TubeParameters parameters) : parameters_(parameters) {
  if (parameters_.cells < 3) throw std::invalid_argument("tube1d: at least 3 cells are needed");
  pressure_ = Eigen::VectorXd::Constant(parameters_.cells + 1, parameters_.initial_pressure);
  area_.resize(parameters_.cells + 1);
  for (Eigen::Index i = 0; i < area_.size(); ++i) area_(i) = area_of(pressure_(i));
}

double TubeWall::area_of(double p) const {
  // a = a0 ((p0 - 2 rho c^2) / (p - 2 rho c^2))^2
  const double two_rho_c2 = 2.0 * parameters_.density * parameters_.wave_speed_squared();
  const double q = (parameters_.reference_pressure - two_rho_c2) / (p - two_rho_c2);
  return parameters_.reference_area * q * q;
}

double TubeWall::pressure_of(double a) const {
  // p = 2 rho c^2 - (2 rho c^2 - p0) sqrt(a0 / a)
  const double two_rho_c2 = 2.0 * parameters_.density * parameters_.wave_speed_squared();
  return two_rho_c2 -
         (two_rho_c2 - parameters_.reference_pressure) * std::sqrt(parameters_.reference_area / a);
}

void TubeWall::set_pressure(const Eigen::VectorXd& p) {
  if (p.size() != pressure_.size())
    throw std::invalid_argument("tube1d wall: pressure has " + std::to_string(p.size()) +
                                " values, expected " + std::to_string(pressure_.size()));
  pressure_ = p;
}

void TubeWall::advance(double dt) {
  for (Eigen::Index i = 0; i < area_.size(); ++i) area_(i) = area_of(pressure_(i));
  time_ += dt;
}

void TubeWall::set_state(const Eigen::VectorXd& pressure, const Eigen::VectorXd& area,
                         double time) {
  set_pressure(pressure);
  if (area.size() != area_.size())
    throw std::invalid_argument("tube1d wall: area has " + std::to_string(area.size()) +
                                " values, expected " + std::to_string(area_.size()));
  area_ = area;
  time_ = time;
}

}  // namespace partita::tube1d
