#pragma once
// What `partita check` puts in place of an external program (solver: external, a program that
// joins over MPI through partita::mpi::ExternalParticipant): its meshes, fields and monitor
// quantities are only known when it joins (the handshake), so the check builds the rest of the
// case against a stand-in whose meshes are what the case's exchanges say it reads and writes,
// each with the points of the exchange's other end (so the mappers build), and which reports
// whatever quantity the case names. It never runs: a check runs no window.

#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "partita/coupling/participant.hpp"
#include "partita/interface/error.hpp"

namespace partita::run {

class ExternalStandIn final : public coupling::Participant {
 public:
  ExternalStandIn(std::string name, std::vector<InterfaceMesh> meshes)
      : coupling::Participant(std::move(name)), meshes_(std::move(meshes)) {}

  const std::vector<InterfaceMesh>& meshes() const override { return meshes_; }
  void initial_values(std::span<coupling::WindowOutput>) override { not_run(); }
  void run_window(const coupling::TimeWindow&, std::span<const coupling::WindowInput>,
                  std::span<coupling::WindowOutput>) override {
    not_run();
  }
  int substeps(double) const override { return 1; }
  double stable_time_step() const override { return std::numeric_limits<double>::infinity(); }
  void save_checkpoint() override { not_run(); }
  void restore_checkpoint() override { not_run(); }
  std::vector<MonitorValue> monitors() const override { return {}; }
  std::vector<MonitorValue> monitor_values(const std::vector<std::string>&) const override {
    return {};
  }
  std::string check_state() const override { return {}; }
  std::optional<double> interface_work(std::string_view) const override { return std::nullopt; }
  void write_output(const OutputFrame&) override {}
  std::vector<std::pair<std::string, std::string>> output_files() const override { return {}; }
  bool supports_restart() const override { return true; }  // (the program says so when it joins)
  void write_restart(BinaryWriter&) const override { not_run(); }
  void read_restart(BinaryReader&) override { not_run(); }
  void finalize() override {}

 private:
  [[noreturn]] void not_run() const {
    throw Error("participant '" + name() +
                "' is an external program, which a check does not run (partita check)");
  }
  std::vector<InterfaceMesh> meshes_;
};

}  // namespace partita::run
