#include "partita/coupling/participant.hpp"

#include <fmt/format.h>

#include "partita/coupling/stopwatch.hpp"
#include "partita/coupling/time_window.hpp"
#include "partita/interface/error.hpp"

namespace partita::coupling {

Participant::Participant(std::string name, std::unique_ptr<Solver> solver, Substeps substeps)
    : name_(std::move(name)), solver_(std::move(solver)), substeps_(substeps) {
  if (!solver_) throw Error("participant '" + name_ + "' has no solver");
  if (!substeps_.automatic && substeps_.count < 1)
    throw Error("participant '" + name_ + "': substeps must be >= 1, found " +
                std::to_string(substeps_.count));
}

const InterfaceMesh* Participant::find_mesh(std::string_view mesh) const {
  for (const auto& m : solver_->meshes())
    if (m.mesh.name() == mesh) return &m;
  return nullptr;
}

int Participant::substeps(double window_size) const {
  const double stable = solver_->stable_time_step();
  if (!substeps_.automatic) {
    // The stable step may fall during a run (a DEM whose granules break into smaller ones).
    if (window_size / substeps_.count > stable * (1.0 + 1e-12))
      throw Error(fmt::format(
          "participant '{}': its stable time step has fallen to {:.4g} s, below the {:.4g} s of "
          "coupling.substeps.{} = {}; use substeps: {{{}: {}}} or more, or {{{}: auto}}",
          name_, stable, window_size / substeps_.count, name_, substeps_.count, name_,
          TimeWindow::substeps_for(window_size, stable), name_));
    return substeps_.count;
  }
  if (!(stable > 0.0))
    throw Error("participant '" + name_ + "': stable_time_step() returned " +
                std::to_string(stable) +
                "; substeps: auto needs a positive step (give a fixed number instead)");
  return TimeWindow::substeps_for(window_size, stable);
}

void Participant::read(std::string_view mesh, std::string_view data,
                       const Eigen::MatrixXd& values) {
  Stopwatch s;
  solver_->read(mesh, data, values);
  seconds_ += s.seconds();
}

void Participant::write(std::string_view mesh, std::string_view data, Eigen::MatrixXd& values) {
  Stopwatch s;
  solver_->write(mesh, data, values);
  seconds_ += s.seconds();
}

void Participant::advance(double dt) {
  Stopwatch s;
  solver_->advance(dt);
  seconds_ += s.seconds();
}

void Participant::save_checkpoint() {
  Stopwatch s;
  solver_->save_checkpoint();
  seconds_ += s.seconds();
}

void Participant::restore_checkpoint() {
  Stopwatch s;
  solver_->restore_checkpoint();
  seconds_ += s.seconds();
}

}  // namespace partita::coupling
