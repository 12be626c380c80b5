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
  if (!fm || !tm) throw Error("exchange " + label() + ": unknown mesh");
  from_points_ = fm->mesh.size();
  source_mesh_ = &fm->mesh;
  target_mesh_ = &tm->mesh;
  if (!mapper_ && fm->mesh.size() != tm->mesh.size())
    throw Error("exchange " + label() +
                ": without a mapper the meshes need the same number of points (" +
                std::to_string(fm->mesh.size()) + " and " + std::to_string(tm->mesh.size()) + ")");
}

std::string Exchange::label() const {
  return "'" + data_ + "' " + from_.participant->name() + "." + from_.mesh + " -> " +
         to_.participant->name() + "." + to_.mesh;
}

void Exchange::check_shape(const Eigen::MatrixXd& values, const char* what) const {
  if (values.rows() != from_points_ || values.cols() != spec_.components)
    throw Error("exchange " + label() + ": participant '" + from_.participant->name() + "' " +
                what + " a " + std::to_string(values.rows()) + " x " +
                std::to_string(values.cols()) + " array; expected " + std::to_string(from_points_) +
                " x " + std::to_string(spec_.components) + " (points of mesh '" + from_.mesh +
                "' x components)");
}

void Exchange::begin_collect() {
  collected_ = 0;
}

void Exchange::collect(const Eigen::MatrixXd& values) {
  check_shape(values, "wrote");
  ++collected_;
  if (writer_combines_ != WriterCombines::average || collected_ == 1) {
    accumulated_ = values;
    return;
  }
  // running mean f̄_k = f̄_{k-1} + (f_k - f̄_{k-1}) / k: exact for a constant output.
  // (The divisions dominate a window's core time: elementwise.hpp halves them where it can.)
  elementwise::mean_step(accumulated_.data(), values.data(), values.size(),
                         static_cast<double>(collected_));
}

void Exchange::collect_taking(Eigen::MatrixXd& values) {
  if (writer_combines_ == WriterCombines::average && collected_ > 0) return collect(values);
  check_shape(values, "wrote");
  ++collected_;
  accumulated_.swap(values);  // where collect() copies
}

void Exchange::finish_collect() {
  // average: f_{n+1} = 1/m Σ_{k=1..m} f_{n,k} (the running mean);  last: f_{n+1} = f_{n,m}
  combined_is_sent_ = false;
  if (collected_ == 0) {
    combined_.setZero(from_points_, spec_.components);
    return;
  }
  // The next begin_collect()/collect() overwrite accumulated_ whole: swap instead of a copy.
  combined_.swap(accumulated_);
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

const Eigen::MatrixXd& Exchange::read_at(double fraction, Eigen::MatrixXd& scratch) const {
  if (reader_sees_ == ReaderSees::constant || fraction >= 1.0 || start_is_end_) return end_;
  // d_{n,k} = d_n + (k/m) (d_{n+1} - d_n)
  scratch.resize(end_.rows(), end_.cols());  // (keeps its storage: same shape every substep)
  elementwise::interpolate(scratch.data(), start_.data(), end_.data(), end_.size(), fraction);
  return scratch;
}

void Exchange::initialize(const Eigen::MatrixXd& initial) {
  check_shape(initial, "gave as initial data");
  combined_ = initial;
  combined_is_sent_ = false;
  sent_ = initial;
  previous_ = initial;
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
