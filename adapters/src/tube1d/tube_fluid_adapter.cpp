#include "tube_fluid_adapter.hpp"

#include <fmt/format.h>

#include "partita/interface/error.hpp"
#include "partita/interface/output.hpp"
#include "tube_config.hpp"
#include "tube_mesh.hpp"

namespace partita::adapters {

TubeFluidAdapter::TubeFluidAdapter(const tube1d::TubeParameters& parameters) : flow_(parameters) {
  InterfaceMesh m;
  m.mesh = tube_nodes(parameters);
  m.writes.push_back(DataSpec{"pressure", 1, "Pa", DataKind::intensive});
  m.reads.push_back(DataSpec{"cross_section_area", 1, "m^2", DataKind::intensive});
  meshes_.push_back(std::move(m));
  checkpoint_ = flow_.state();
}

void TubeFluidAdapter::read(std::string_view mesh, std::string_view data,
                            const Eigen::MatrixXd& values) {
  if (mesh != "nodes" || data != "cross_section_area")
    throw Error("tube1d-fluid reads only 'cross_section_area' on mesh 'nodes', not '" +
                std::string(data) + "' on '" + std::string(mesh) + "'");
  flow_.set_area(values.col(0));
}

void TubeFluidAdapter::write(std::string_view mesh, std::string_view data,
                             Eigen::MatrixXd& values) {
  if (mesh != "nodes" || data != "pressure")
    throw Error("tube1d-fluid writes only 'pressure' on mesh 'nodes', not '" + std::string(data) +
                "' on '" + std::string(mesh) + "'");
  values = flow_.pressure();
}

void TubeFluidAdapter::advance(double dt) {
  try {
    flow_.advance(dt);
  } catch (const std::exception& e) {
    throw Error(std::string("tube1d-fluid: ") + e.what() +
                "; if this happens during coupling iterations, the iteration probably diverged "
                "(use a smaller "
                "relaxation factor, aitken or iqn-ils)");
  }
}

void TubeFluidAdapter::write_output(const OutputFrame& frame) {
  const std::string file = fmt::format("{}_tube_{:06d}.vtp", frame.prefix, frame.index);
  write_vtp(frame.vtk_directory / file, meshes_.front().mesh,
            {{"velocity", flow_.velocity()},
             {"pressure", flow_.pressure()},
             {"cross_section_area", flow_.area()}},
            {}, nullptr, frame.vtk);
  files_ = {{"tube", file}};
}

void TubeFluidAdapter::write_restart(BinaryWriter& out) const {
  const auto& s = flow_.state();
  out.section("tube1d-fluid");
  out.write(s.velocity);
  out.write(s.pressure);
  out.write(s.area);
  out.write(s.time);
}

void TubeFluidAdapter::read_restart(BinaryReader& in) {
  in.expect_section("tube1d-fluid");
  tube1d::TubeFlow::State s;
  in.read(s.velocity);
  in.read(s.pressure);
  in.read(s.area);
  in.read(s.time);
  const Eigen::Index n = flow_.state().pressure.size();
  if (s.velocity.size() != n || s.pressure.size() != n || s.area.size() != n)
    in.fail(std::to_string(n) + " node values of the tube (same cells as the case)");
  flow_.set_state(s);
}

const MonitorTable<TubeFluidAdapter>& TubeFluidAdapter::monitor_table() {
  static const MonitorTable<TubeFluidAdapter> table = [] {
    using A = TubeFluidAdapter;
    MonitorTable<A> t;
    t.scalar("inlet_pressure", "Pa", "pressure in the first cell",
             [](const A& a) { return a.flow_.pressure()(0); });
    t.scalar("outlet_pressure", "Pa", "pressure in the last cell", [](const A& a) {
      const auto& p = a.flow_.pressure();
      return p(p.size() - 1);
    });
    t.scalar("inlet_velocity", "m/s", "velocity in the first cell",
             [](const A& a) { return a.flow_.velocity()(0); });
    return t;
  }();
  return table;
}

std::shared_ptr<const config::Spec> TubeFluidAdapter::spec() {
  static const auto s =
      tube_spec("tube1d-fluid", "quasi-1D incompressible flow in the elastic tube", true);
  return s;
}

std::unique_ptr<Solver> TubeFluidAdapter::create(const SolverContext& context) {
  return std::make_unique<TubeFluidAdapter>(tube_parameters(context.config, true));
}

}  // namespace partita::adapters
