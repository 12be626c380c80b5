#include "partita/coupling/participant.hpp"

#include <fmt/format.h>

#include "partita/coupling/elementwise.hpp"
#include "partita/coupling/stopwatch.hpp"
#include "partita/coupling/time_window.hpp"
#include "partita/interface/error.hpp"

namespace partita::coupling {

const InterfaceMesh* Participant::find_mesh(std::string_view mesh) const {
  for (const auto& m : meshes())
    if (m.mesh.name() == mesh) return &m;
  return nullptr;
}

const Eigen::MatrixXd& input_at(const WindowInput& in, double fraction, Eigen::MatrixXd& scratch) {
  if (in.sees == ReaderSees::constant || fraction >= 1.0 || in.start_is_end) return *in.end;
  // d_n + s (d_{n+1} - d_n), s the fraction of the window (k/m at the end of substep k)
  scratch.resize(in.end->rows(), in.end->cols());  // (keeps its storage: same shape)
  elementwise::interpolate(scratch.data(), in.start->data(), in.end->data(), in.end->size(),
                           fraction);
  return scratch;
}

LocalParticipant::LocalParticipant(std::string name, std::unique_ptr<Solver> solver,
                                   Substeps substeps)
    : Participant(std::move(name)), solver_(std::move(solver)), substeps_(substeps) {
  if (!solver_) throw Error("participant '" + this->name() + "' has no solver");
  if (!substeps_.automatic && substeps_.count < 1)
    throw Error("participant '" + this->name() + "': substeps must be >= 1, found " +
                std::to_string(substeps_.count));
}

int LocalParticipant::substeps(double window_size) const {
  const double stable = solver_->stable_time_step();
  if (!substeps_.automatic) {
    // The stable step may fall during a run (a DEM whose granules break into smaller ones).
    if (TimeWindow::longer_than(window_size / substeps_.count, stable))
      throw Error(fmt::format(
          "participant '{}': its stable time step has fallen to {:.4g} s, below the {:.4g} s of "
          "coupling.substeps.{} = {}; use substeps: {{{}: {}}} or more, or {{{}: auto}}",
          name(), stable, window_size / substeps_.count, name(), substeps_.count, name(),
          TimeWindow::substeps_for(window_size, stable), name()));
    return substeps_.count;
  }
  if (!(stable > 0.0))
    throw Error("participant '" + name() + "': stable_time_step() returned " +
                std::to_string(stable) +
                "; substeps: auto needs a positive step (give a fixed number instead)");
  return TimeWindow::substeps_for(window_size, stable);
}

namespace {

void check_shape(const WindowOutput& o, const Eigen::MatrixXd& values, const std::string& who,
                 const char* what) {
  if (values.rows() != o.points || values.cols() != o.components)
    throw Error("exchange " + *o.label + ": participant '" + who + "' " + what + " a " +
                std::to_string(values.rows()) + " x " + std::to_string(values.cols()) +
                " array; expected " + std::to_string(o.points) + " x " +
                std::to_string(o.components) + " (points of mesh '" + *o.mesh + "' x components)");
}

}  // namespace

void LocalParticipant::initial_values(std::span<WindowOutput> outputs) {
  for (WindowOutput& o : outputs) {
    Stopwatch s;
    solver_->write(*o.mesh, *o.data, *o.combined);
    add_seconds(s.seconds());
    check_shape(o, *o.combined, name(), "gave as initial data");
  }
}

// One substep's value of output o into its combination (storage taken where it would be
// copied: the first substep of an average, every substep of `last`; the solver's next write()
// sets, and sizes, every value of the buffer it is given).
void LocalParticipant::collect(const WindowOutput& o, Collect& c) {
  check_shape(o, c.written, name(), "wrote");
  ++c.count;
  if (o.combines == WriterCombines::average && c.count > 1) {
    // running mean f̄_k = f̄_{k-1} + (f_k - f̄_{k-1}) / k: exact for a constant output.
    // (The divisions dominate a window's core time: elementwise.hpp halves them where it can.)
    elementwise::mean_step(c.accumulated.data(), c.written.data(), c.written.size(),
                           static_cast<double>(c.count));
    return;
  }
  c.accumulated.swap(c.written);
}

void LocalParticipant::run_window(const TimeWindow& window, std::span<const WindowInput> inputs,
                                  std::span<WindowOutput> outputs) {
  TimeWindow w = window.with_substeps(substeps(window.size()));
  if (collect_.size() != outputs.size()) collect_.resize(outputs.size());
  if (read_scratch_.size() != inputs.size()) {
    read_scratch_.resize(inputs.size());
    read_values_.resize(inputs.size());
  }
  for (Collect& c : collect_) c.count = 0;
  struct Current {  // what current_window() and current_inputs() give while the window runs
    LocalParticipant& p;
    Current(LocalParticipant& q, const TimeWindow& w, std::span<const WindowInput> in) : p(q) {
      p.current_window_ = &w;
      p.current_inputs_ = in;
    }
    ~Current() {
      p.current_window_ = nullptr;
      p.current_inputs_ = {};
    }
  } current(*this, w, inputs);
  // for k = 0..m-1: read d(t_{n,k+1}); advance(t_{n,k+1} - t_{n,k}); write f_{n,k+1}
  while (!w.end_reached()) {
    const double fraction = w.fraction_at(w.substep() + 1);
    for (std::size_t i = 0; i < inputs.size(); ++i)  // the time interpolation
      read_values_[i] = &input_at(inputs[i], fraction, read_scratch_[i]);
    {
      // The solver's own work, read + advance + write, timed as one: one clock pair per
      // substep rather than one per call (a clock read costs 20-50 ns; 6 substeps a window).
      const Stopwatch s;
      for (std::size_t i = 0; i < inputs.size(); ++i)
        solver_->read(*inputs[i].mesh, *inputs[i].data, *read_values_[i]);
      solver_->advance(w.next_substep_size());
      for (std::size_t j = 0; j < outputs.size(); ++j)
        solver_->write(*outputs[j].mesh, *outputs[j].data, collect_[j].written);
      add_seconds(s.seconds());
    }
    w.advance_substep();
    for (std::size_t j = 0; j < outputs.size(); ++j)  // the combination over the substeps
      collect(outputs[j], collect_[j]);
  }
  // average: f_{n+1} = 1/m sum_{k=1..m} f_{n,k} (the running mean);  last: f_{n+1} = f_{n,m}
  for (std::size_t j = 0; j < outputs.size(); ++j) {
    Collect& c = collect_[j];
    if (c.count == 0)
      outputs[j].combined->setZero(outputs[j].points, outputs[j].components);
    else
      outputs[j].combined->swap(c.accumulated);  // the next window overwrites accumulated whole
  }
}

void LocalParticipant::save_checkpoint() {
  Stopwatch s;
  solver_->save_checkpoint();
  add_seconds(s.seconds());
}

void LocalParticipant::restore_checkpoint() {
  Stopwatch s;
  solver_->restore_checkpoint();
  add_seconds(s.seconds());
}

}  // namespace partita::coupling
