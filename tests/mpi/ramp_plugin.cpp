// A solver plugin for the external-code API's read test (tests/mpi/external_read.yaml): solver
// `ramp` writes on its mesh "points" (three points on the x axis) a field linear in time,
//   value_i(t) = c_i + r_i t,
// known exactly to the reading program (tests/mpi/read_probe.cpp), which checks what the API
// gives it at any time of a step against it.
#include <array>

#include "partita/coupling/plugin.hpp"
#include "partita/interface/config.hpp"
#include "partita/interface/solver.hpp"

namespace {

class Ramp final : public partita::Solver {
 public:
  static constexpr std::array<double, 3> c = {1.0, -2.0, 0.5};   // value at t = 0
  static constexpr std::array<double, 3> r = {3.0, -7.0, 0.25};  // rate [1/s]

  Ramp() {
    partita::Mesh::Points x = partita::Mesh::Points::Zero(3, 3);
    for (int i = 0; i < 3; ++i) x(i, 0) = i;
    meshes_.push_back({partita::Mesh("points", x),
                       {},
                       {{"value", 1, "1", partita::DataKind::intensive}}});
  }
  const std::vector<partita::InterfaceMesh>& meshes() const override { return meshes_; }
  void read(std::string_view, std::string_view, const Eigen::MatrixXd&) override {}
  void write(std::string_view, std::string_view, Eigen::MatrixXd& values) override {
    values.resize(3, 1);
    for (int i = 0; i < 3; ++i) values(i, 0) = c[i] + r[i] * t_;
  }
  void advance(double dt) override { t_ += dt; }
  double time() const override { return t_; }
  void save_checkpoint() override { saved_ = t_; }
  void restore_checkpoint() override { t_ = saved_; }

 private:
  std::vector<partita::InterfaceMesh> meshes_;
  double t_ = 0.0, saved_ = 0.0;
};

}  // namespace

PARTITA_PLUGIN(registries) {
  registries.solvers.add(
      "ramp", "writes value_i = c_i + r_i t on three points (the external API's read test)",
      [](const partita::SolverContext&) -> std::unique_ptr<partita::Solver> {
        return std::make_unique<Ramp>();
      });
}
