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
  if (scale_ != 1.0) end_ *= scale_;  // a test's broken exchange
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
// d_{n+1} writes d_{n+1} twice; a reader gets them as two arrays.
template <class Archive, class Self>
void Exchange::serialize(Archive& ar, Self& x) {
  ar.io_section("exchange " + x.label());
  if constexpr (!Archive::reading) {
    for (const Eigen::MatrixXd* m :
         {&x.combined(), &x.sent_, &x.previous_, x.start_is_end_ ? &x.end_ : &x.start_, &x.end_})
      ar.io(*m);
  } else {
    for (Eigen::MatrixXd* m : {&x.combined_, &x.sent_, &x.previous_, &x.start_, &x.end_})
      ar.io(*m);
    x.combined_is_sent_ = false;
    x.start_is_end_ = false;
    const Eigen::Index sender = x.from_points_;
    const Eigen::Index receiver = x.target_mesh_->size();
    for (const Eigen::MatrixXd* m : {&x.combined_, &x.sent_, &x.previous_})
      if (m->rows() != sender || m->cols() != x.spec_.components)
        ar.fail(fmt::format("{} x {} values of {} (the sender's mesh)", sender,
                            x.spec_.components, x.label()));
    for (const Eigen::MatrixXd* m : {&x.start_, &x.end_})
      if (m->rows() != receiver || m->cols() != x.spec_.components)
        ar.fail(fmt::format("{} x {} values of {} (the receiver's mesh)", receiver,
                            x.spec_.components, x.label()));
  }
}

void Exchange::write_state(BinaryWriter& out) const { serialize(out, *this); }

void Exchange::read_state(BinaryReader& in) { serialize(in, *this); }

}  // namespace partita::coupling
