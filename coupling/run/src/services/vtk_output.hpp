#pragma once
// VTK output: frames of every participant (its own files, listed in DIR/vtk/<participant>_<series>
// .pvd) and of its interface meshes with the data exchanged there, for the initial state, every
// output.every seconds and after the last window.

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "partita/coupling/exchange.hpp"
#include "partita/coupling/participant.hpp"
#include "partita/interface/output.hpp"
#include "partita/run/service.hpp"

namespace partita::run {

class VtkOutput final : public Service {
 public:
  VtkOutput(const std::filesystem::path& output_dir, double every, double window_size,
            vtk::Options options, std::vector<coupling::Participant*> participants,
            std::vector<const coupling::Exchange*> exchanges);

  void observe(coupling::FinishedWindow& w) override;
  std::string section() const override { return "vtk"; }
  void serialize(StateArchive& ar) override;
  void restored() override;
  void report(RunSummary& summary) const override;

  /// The two parts of its section: the frame count and the next output time; the series.
  /// (Restart files of format 5 keep them apart.)
  void serialize_frames(StateArchive& ar);
  void serialize_series(StateArchive& ar);

 private:
  void write(int frame, double time);
  PvdSeries& pvd(const std::string& series);

  std::filesystem::path vtk_dir_;
  double every_;  // 0: first and last frame only
  double window_size_;
  vtk::Options options_;
  std::vector<coupling::Participant*> participants_;
  std::vector<const coupling::Exchange*> exchanges_;
  int frame_ = 0;
  double next_output_ = 0.0;
  bool respace_ = false;  // resumed: the next frame time follows this run's every_ (observe())
  std::vector<std::pair<std::string, PvdSeries>> pvds_;  // series name -> .pvd
  double seconds_ = 0.0;                                 // output time
  struct Restored {
    int frame = 0;
    double next_output = 0.0;
    std::vector<std::pair<std::string, std::vector<std::pair<double, std::string>>>> pvds;
  } restored_;
};

}  // namespace partita::run
