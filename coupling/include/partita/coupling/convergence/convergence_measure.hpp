#pragma once
// A convergence measure of an implicit scheme on one data field (template method: this base
// owns the flow and the comparison with the limit; a subclass computes the measured value).
//
// Call order: for every window: new_window(); for every iteration:
// measure(previous, current) then converged() / value(). `previous` is the field as the readers
// saw it in this iteration, `current` what its writer returned.
// All measures of a scheme must hold for a window to converge (a combined measure).

#include <memory>
#include <string>

#include <Eigen/Core>

#include "partita/interface/config.hpp"

namespace partita::coupling {

class ConvergenceMeasure {
 public:
  ConvergenceMeasure(std::string data, double limit) : data_(std::move(data)), limit_(limit) {}
  virtual ~ConvergenceMeasure() = default;

  void new_window() {
    iteration_ = 0;
    reset();
  }
  void measure(const Eigen::VectorXd& previous, const Eigen::VectorXd& current) {
    ++iteration_;
    value_ = compute(previous, current);
  }
  bool converged() const { return value_ <= limit_; }
  /// The measured value of the last iteration (compared with limit()).
  double value() const { return value_; }
  double limit() const { return limit_; }
  const std::string& data() const { return data_; }
  /// Registered name ("relative", ...).
  virtual std::string name() const = 0;
  /// Unit of value(): "" when dimensionless, else the data's unit.
  virtual bool dimensionless() const { return true; }

 protected:
  /// The measured value for this iteration.
  virtual double compute(const Eigen::VectorXd& previous, const Eigen::VectorXd& current) = 0;
  /// Forget per-window state.
  virtual void reset() {}
  int iteration() const { return iteration_; }

 private:
  std::string data_;
  double limit_;
  double value_ = 0.0;
  int iteration_ = 0;
};

/// The parameters every measure takes: type, data, limit.
std::shared_ptr<config::Spec> convergence_spec(const std::string& name, const std::string& doc);

}  // namespace partita::coupling
