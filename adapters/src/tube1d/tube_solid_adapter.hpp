#pragma once
// Adapter of the tube wall (solvers/tube1d TubeWall) to the Solver contract.
// Mesh "nodes": the N + 1 nodes on the x axis. Reads "pressure" [Pa]; writes
// "cross_section_area" [m^2]. Monitors: mid_area, max_area [m^2].

#include <memory>
#include <vector>

#include "partita/interface/monitor_table.hpp"
#include "partita/interface/solver.hpp"
#include "partita/tube1d/tube_wall.hpp"

namespace partita::adapters {

class TubeSolidAdapter : public Solver {
 public:
  explicit TubeSolidAdapter(const tube1d::TubeParameters& parameters);

  const std::vector<InterfaceMesh>& meshes() const override { return meshes_; }
  void read(std::string_view mesh, std::string_view data, const Eigen::MatrixXd& values) override;
  void write(std::string_view mesh, std::string_view data, Eigen::MatrixXd& values) override;
  void advance(double dt) override { wall_.advance(dt); }
  double time() const override { return wall_.time(); }
  void save_checkpoint() override { checkpoint_ = wall_; }
  void restore_checkpoint() override { wall_ = checkpoint_; }
  void write_output(const OutputFrame& frame) override;
  bool supports_restart() const override { return true; }
  void write_restart(BinaryWriter& out) const override;
  void read_restart(BinaryReader& in) override;
  std::vector<std::pair<std::string, std::string>> output_files() const override { return files_; }
  std::vector<MonitorValue> monitors() const override { return monitor_values({}); }
  std::vector<MonitorValue> monitor_values(const std::vector<std::string>& names) const override {
    return monitor_table().values(*this, names);
  }

  static std::shared_ptr<const config::Spec> spec();
  static std::unique_ptr<Solver> create(const SolverContext& context);
  /// The monitor quantities: their docs (registration) and values.
  static const MonitorTable<TubeSolidAdapter>& monitor_table();

 private:
  tube1d::TubeWall wall_;
  tube1d::TubeWall checkpoint_;
  std::vector<InterfaceMesh> meshes_;
  std::vector<std::pair<std::string, std::string>> files_;
};

}  // namespace partita::adapters
