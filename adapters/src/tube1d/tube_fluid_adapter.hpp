#pragma once
// Adapter of the tube's flow solver (solvers/tube1d TubeFlow) to the Solver contract.
// Mesh "nodes": the N + 1 nodes on the x axis. Writes "pressure" [Pa]; reads
// "cross_section_area" [m^2] (the area at the end of the step). Monitors: inlet_pressure,
// outlet_pressure [Pa], inlet_velocity [m/s]. Checkpoint: the flow's state (a value).

#include <memory>
#include <vector>

#include "partita/interface/monitor_table.hpp"
#include "partita/interface/solver.hpp"
#include "partita/tube1d/tube_flow.hpp"

namespace partita::adapters {

class TubeFluidAdapter : public Solver {
 public:
  explicit TubeFluidAdapter(const tube1d::TubeParameters& parameters);

  const std::vector<InterfaceMesh>& meshes() const override { return meshes_; }
  void read(std::string_view mesh, std::string_view data, const Eigen::MatrixXd& values) override;
  void write(std::string_view mesh, std::string_view data, Eigen::MatrixXd& values) override;
  void advance(double dt) override;
  double time() const override { return flow_.time(); }
  void save_checkpoint() override { checkpoint_ = flow_.state(); }
  void restore_checkpoint() override { flow_.set_state(checkpoint_); }
  void write_output(const OutputFrame& frame) override;
  bool supports_restart() const override { return true; }
  void write_restart(BinaryWriter& out) const override;
  void read_restart(BinaryReader& in) override;
  std::vector<std::pair<std::string, std::string>> output_files() const override { return files_; }
  std::vector<MonitorValue> monitors() const override { return monitor_values({}); }
  std::vector<MonitorValue> monitor_values(const std::vector<std::string>& names) const override {
    return monitor_table().values(*this, names);
  }

  const tube1d::TubeFlow& flow() const { return flow_; }

  static std::shared_ptr<const config::Spec> spec();
  static std::unique_ptr<Solver> create(const SolverContext& context);
  /// The monitor quantities: their docs (registration) and values.
  static const MonitorTable<TubeFluidAdapter>& monitor_table();

 private:
  tube1d::TubeFlow flow_;
  tube1d::TubeFlow::State checkpoint_;
  std::vector<InterfaceMesh> meshes_;
  std::vector<std::pair<std::string, std::string>> files_;
};

}  // namespace partita::adapters
