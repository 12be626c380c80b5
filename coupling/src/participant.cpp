#include "partita/coupling/participant.hpp"

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
  if (!substeps_.automatic) return substeps_.count;
  const double stable = solver_->stable_time_step();
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
