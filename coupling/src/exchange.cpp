#include "partita/coupling/exchange.hpp"

#include <fmt/format.h>

#include "elementwise.hpp"
#include "partita/coupling/stopwatch.hpp"
#include "partita/interface/binary_io.hpp"
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
  return WindowInput{&to_.mesh, &data_, reader_sees_, &start_, &end_, start_is_end_};
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

void Exchange::write_state(BinaryWriter& out) const {
  out.section("exchange " + label());
  for (const Eigen::MatrixXd* m :
       {&combined(), &sent_, &previous_, start_is_end_ ? &end_ : &start_, &end_})
    out.write(*m);
}

void Exchange::read_state(BinaryReader& in) {
  in.expect_section("exchange " + label());
  for (Eigen::MatrixXd* m : {&combined_, &sent_, &previous_, &start_, &end_}) in.read(*m);
  combined_is_sent_ = false;
  start_is_end_ = false;
  const Eigen::Index sender = from_points_;
  const Eigen::Index receiver = target_mesh_->size();
  for (const Eigen::MatrixXd* m : {&combined_, &sent_, &previous_})
    if (m->rows() != sender || m->cols() != spec_.components)
      in.fail(fmt::format("{} x {} values of {} (the sender's mesh)", sender, spec_.components,
                          label()));
  for (const Eigen::MatrixXd* m : {&start_, &end_})
    if (m->rows() != receiver || m->cols() != spec_.components)
      in.fail(fmt::format("{} x {} values of {} (the receiver's mesh)", receiver, spec_.components,
                          label()));
}

}  // namespace partita::coupling
