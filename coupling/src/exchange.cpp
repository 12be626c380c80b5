#include "partita/coupling/exchange.hpp"

#include <utility>

#include <fmt/format.h>

#include "partita/coupling/elementwise.hpp"
#include "partita/coupling/stopwatch.hpp"
#include "partita/interface/state_archive.hpp"
#include "partita/interface/error.hpp"

namespace partita::coupling {

Exchange::Exchange(std::string data, End from, End to, DataSpec spec,
                   std::unique_ptr<Mapper> mapper, ReaderSees reader_sees,
                   WriterCombines writer_combines)
    : data_(std::move(data)),
      from_(std::move(from)),
      to_(std::move(to)),
      spec_(std::move(spec)),
      mapper_(std::move(mapper)),
      reader_sees_(reader_sees),
      writer_combines_(writer_combines) {
  const InterfaceMesh* fm = from_.participant->find_mesh(from_.mesh);
  const InterfaceMesh* tm = to_.participant->find_mesh(to_.mesh);
  if (!fm || !tm)
    throw Error("exchange '" + data_ + "' " + from_.participant->name() + "." + from_.mesh +
                " -> " + to_.participant->name() + "." + to_.mesh + ": unknown mesh");
  label_ = "'" + data_ + "' " + from_.participant->name() + "." + from_.mesh + " -> " +
           to_.participant->name() + "." + to_.mesh;
  from_points_ = fm->mesh.size();
  source_mesh_ = &fm->mesh;
  target_mesh_ = &tm->mesh;
  if (!mapper_ && fm->mesh.size() != tm->mesh.size())
    throw Error("exchange " + label() +
                ": without a mapper the meshes need the same number of points (" +
                std::to_string(fm->mesh.size()) + " and " + std::to_string(tm->mesh.size()) + ")");
}

WindowOutput Exchange::window_output() {
  combined_is_sent_ = false;  // the writer fills combined_ (its own storage again)
  return WindowOutput{&from_.mesh, &data_, writer_combines_, from_points_, spec_.components,
                      &label_, &combined_};
}

WindowInput Exchange::window_input() const {
  WindowInput in{&to_.mesh, &data_, reader_sees_, &start_, &end_, start_is_end_};
  if (mapped_by_receiver_) {  // end = scale M sent (transmit()); start = scale M sent_start_
    in.sent_end = &sent_;
    if (sent_start_known_) in.sent_start = &sent_start_;
  }
  return in;
}

Eigen::MatrixXd& Exchange::sent() {
  if (combined_is_sent_) {  // the caller may change sent: combined keeps its own copy
    combined_ = sent_;
    combined_is_sent_ = false;
  }
  return sent_;
}

void Exchange::send_combined() {
  if (combined_is_sent_) return;
  sent_.swap(combined_);
  combined_is_sent_ = true;
}

void Exchange::transmit() {
  Stopwatch s;
  if (start_is_end_) {
    start_.swap(end_);  // d_n keeps the accepted value; end_'s storage is overwritten below
    start_is_end_ = false;
  }
  if (mapper_)
    mapper_->map(sent_, end_);
  else
    end_ = sent_;
  mapping_seconds_ += s.seconds();
}

void Exchange::initialize() {
  combined_is_sent_ = false;
  sent_ = combined_;
  previous_ = combined_;
  transmit();
  start_is_end_ = true;  // start = end
}

// The values carried between windows, one function for writing and reading: combined, sent,
// previous (the sender's mesh), d_n and d_{n+1} (the receiver's). A writer whose d_n equals
// d_{n+1} writes d_{n+1} twice (and whose combined is sent's storage, sent's values); a reader
// gets them as five arrays.
void Exchange::serialize(StateArchive& ar) {
  ar.section("exchange " + label());
  if (!ar.reading()) {
    const Eigen::MatrixXd& start = start_is_end_ ? end_ : start_;
    for (const Eigen::MatrixXd* m : {&combined(), &std::as_const(sent_), &std::as_const(previous_),
                                     &start, &std::as_const(end_)})
      ar.io(*m);
    return;
  }
  for (Eigen::MatrixXd* m : {&combined_, &sent_, &previous_, &start_, &end_}) ar.io(*m);
  combined_is_sent_ = false;
  start_is_end_ = false;
  sent_start_known_ = false;  // d_n's values before the mapping are not in the file
  const Eigen::Index receiver = target_mesh_->size();
  for (const Eigen::MatrixXd* m : {&combined_, &sent_, &previous_})
    if (m->rows() != from_points_ || m->cols() != spec_.components)
      ar.fail(fmt::format("{} x {} values of {} (the sender's mesh)", from_points_,
                          spec_.components, label()));
  for (const Eigen::MatrixXd* m : {&start_, &end_})
    if (m->rows() != receiver || m->cols() != spec_.components)
      ar.fail(fmt::format("{} x {} values of {} (the receiver's mesh)", receiver,
                          spec_.components, label()));
}

}  // namespace partita::coupling
