#pragma once
// A mass on a spring along z (one degree of freedom), as a partita solver: the smallest complete
// adapter. It exposes one mesh, "mass" (one point), writes its displacement and reads a force
// (the force the other participant exerts on it: its motion is the other side's boundary motion,
// the other side's reaction its load). Optionally under gravity along z and with a dashpot.

#include <memory>

#include "partita/interface/config.hpp"
#include "partita/interface/registry.hpp"
#include "partita/interface/solver.hpp"

class OscillatorAdapter final : public partita::Solver {
 public:
  struct State {
    double z = 0.0, v = 0.0, t = 0.0;
  };
  OscillatorAdapter(double mass, double stiffness, State initial, double gravity = 0.0,
                    double damping = 0.0);
  static std::unique_ptr<partita::Solver> create(const partita::SolverContext& context);
  static std::shared_ptr<const partita::config::Spec> spec();
  static std::vector<partita::QuantityDoc> quantities();
  /// Add "oscillator" to a solver registry (the one line both ways of using it share: main.cpp,
  /// a partita with the solver built in; oscillator_plugin.cpp, the plugin for the stock partita).
  static void register_in(partita::Registry<partita::SolverFactory>& solvers);

  const std::vector<partita::InterfaceMesh>& meshes() const override { return meshes_; }
  void read(std::string_view mesh, std::string_view data, const Eigen::MatrixXd& values) override;
  void write(std::string_view mesh, std::string_view data, Eigen::MatrixXd& values) override;
  void advance(double dt) override;
  double time() const override { return s_.t; }
  void save_checkpoint() override { checkpoint_ = s_; }
  void restore_checkpoint() override { s_ = checkpoint_; }
  bool supports_restart() const override { return true; }
  void write_restart(partita::BinaryWriter& out) const override;
  void read_restart(partita::BinaryReader& in) override;
  std::vector<partita::MonitorValue> monitors() const override;

 private:
  double m_, k_, g_, c_, force_ = 0.0;
  State s_, checkpoint_;
  std::vector<partita::InterfaceMesh> meshes_;
};
