#include "vtk_output.hpp"

#include <cmath>

#include <fmt/format.h>

#include "partita/coupling/stopwatch.hpp"
#include "partita/coupling/time_window.hpp"
#include "partita/interface/error.hpp"
#include "partita/run/run_summary.hpp"

namespace partita::run {

using namespace coupling;
namespace fs = std::filesystem;

VtkOutput::VtkOutput(const fs::path& output_dir, double every, double window_size,
                     vtk::Options options, std::vector<Participant*> participants,
                     std::vector<const Exchange*> exchanges)
    : vtk_dir_(output_dir / "vtk"),
      every_(every),
      window_size_(window_size),
      options_(options),
      participants_(std::move(participants)),
      exchanges_(std::move(exchanges)),
      next_output_(every) {}

void VtkOutput::observe(FinishedWindow& w) {
  if (w.initial()) {
    write(frame_++, 0.0);
    return;
  }
  if (respace_) {
    // resumed: with another output.every than the run that wrote the restart, the next frame
    // is the new spacing's first multiple after the restart's time (with the same, the same)
    respace_ = false;
    if (every_ > 0.0) {
      const double resumed_at = w.time - window_size_;
      double k = std::floor(resumed_at / every_);
      while (TimeWindow::reached(resumed_at, k * every_, window_size_)) k += 1.0;
      if (std::abs(k * every_ - next_output_) > 1e-9 * every_) next_output_ = k * every_;
    }
  }
  if ((every_ > 0.0 && TimeWindow::reached(w.time, next_output_, window_size_)) || w.last) {
    write(frame_++, w.time);
    // the next multiple of `every` after this window (a run resumed with another output.every
    // takes up the new spacing from here; the frames keep counting)
    if (every_ > 0.0) {
      double k = static_cast<double>(frame_);
      if (TimeWindow::reached(w.time, k * every_, window_size_) ||
          !TimeWindow::reached(w.time, (k - 1.0) * every_, window_size_))
        k = std::floor(w.time / every_);
      while (TimeWindow::reached(w.time, k * every_, window_size_)) k += 1.0;
      next_output_ = k * every_;
    }
  }
}

PvdSeries& VtkOutput::pvd(const std::string& series) {
  for (auto& [n, s] : pvds_)
    if (n == series) return s;
  pvds_.emplace_back(series, PvdSeries(vtk_dir_ / (series + ".pvd")));
  return pvds_.back().second;
}

void VtkOutput::write(int frame, double time) {
  Stopwatch clock;
  for (Participant* p : participants_) {
    OutputFrame f{vtk_dir_, p->name(), frame, time, options_};
    p->write_output(f);  // counted as output time, not the participant's
    for (const auto& [series, file] : p->output_files()) {
      if (fs::path(file).has_parent_path() || file.empty() || file.front() == '.')
        throw Error("participant '" + p->name() + "' wrote the output file '" + file +
                    "', which is not a plain file name inside " + vtk_dir_.string());
      pvd(p->name() + "_" + series).add(time, file);
    }
    // interface meshes with their exchanged data
    for (const auto& im : p->meshes()) {
      VtkArrays arrays;
      for (const Exchange* e : exchanges_) {
        if (&e->from() == p && e->from_mesh() == im.mesh.name() &&
            e->sent().rows() == im.mesh.size())
          arrays.emplace_back(e->data(), e->sent());
        if (&e->to() == p && e->to_mesh() == im.mesh.name() &&
            e->received().rows() == im.mesh.size())
          arrays.emplace_back(e->data(), e->received());
      }
      if (arrays.empty() || im.mesh.size() > 200000) continue;
      const std::string file =
          fmt::format("{}_interface_{}_{:06d}.vtp", p->name(), im.mesh.name(), frame);
      write_vtp(vtk_dir_ / file, im.mesh, arrays, {}, nullptr, options_);
      pvd(p->name() + "_interface_" + im.mesh.name()).add(time, file);
    }
  }
  seconds_ += clock.seconds();
}

void VtkOutput::serialize(StateArchive& ar) {
  serialize_frames(ar);
  serialize_series(ar);
}

// [i32 frame] [f64 next output time]
void VtkOutput::serialize_frames(StateArchive& ar) {
  if (!ar.reading()) {
    ar.io(frame_);
    ar.io(next_output_);
    return;
  }
  ar.io(restored_.frame);
  ar.io(restored_.next_output);
  if (restored_.frame < 0 || !std::isfinite(restored_.next_output))
    ar.fail("a frame count and an output time");
}

// [u64 count] count x ([text series] [u64 n] n x ([f64 time] [text file]))
void VtkOutput::serialize_series(StateArchive& ar) {
  auto& pvds = restored_.pvds;
  if (!ar.reading()) {
    pvds.clear();
    for (const auto& [series, p] : pvds_) pvds.emplace_back(series, p.entries());
  }
  auto count = static_cast<std::uint64_t>(pvds.size());
  ar.io(count);
  if (ar.reading()) pvds.clear();
  for (std::uint64_t i = 0; i < count; ++i) {
    if (ar.reading()) pvds.emplace_back();
    auto& [series, entries] = pvds[i];
    ar.io(series);
    auto n = static_cast<std::uint64_t>(entries.size());
    ar.io(n);
    if (ar.reading()) {
      entries.clear();
      for (std::uint64_t k = 0; k < n; ++k) {
        double t = 0.0;
        std::string f;
        ar.io(t);
        ar.io(f);
        entries.emplace_back(t, std::move(f));
      }
    } else {
      for (auto& [t, f] : entries) {
        ar.io(t);
        ar.io(f);
      }
    }
  }
  if (!ar.reading()) pvds.clear();
}

void VtkOutput::restored() {
  frame_ = restored_.frame;
  next_output_ = restored_.next_output;
  respace_ = true;
  fs::create_directories(vtk_dir_);
  for (auto& [series, entries] : restored_.pvds) pvd(series).restore_entries(std::move(entries));
  restored_ = Restored{};
}

void VtkOutput::report(RunSummary& summary) const {
  summary.output_seconds += seconds_;
}

}  // namespace partita::run
