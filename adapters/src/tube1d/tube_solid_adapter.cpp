#include "tube_solid_adapter.hpp"

#include <numbers>

#include <fmt/format.h>

#include "partita/interface/error.hpp"
#include "partita/interface/output.hpp"
#include "tube_config.hpp"
#include "tube_mesh.hpp"

namespace partita::adapters {

TubeSolidAdapter::TubeSolidAdapter(const tube1d::TubeParameters& parameters)
    : wall_(parameters), checkpoint_(parameters) {
  InterfaceMesh m;
  m.mesh = tube_nodes(parameters);
  m.reads.push_back(DataSpec{"pressure", 1, "Pa", DataKind::intensive});
  m.writes.push_back(DataSpec{"cross_section_area", 1, "m^2", DataKind::intensive});
  meshes_.push_back(std::move(m));
}

void TubeSolidAdapter::read(std::string_view mesh, std::string_view data,
                            const Eigen::MatrixXd& values) {
  if (mesh != "nodes" || data != "pressure")
    throw Error("tube1d-solid reads only 'pressure' on mesh 'nodes', not '" + std::string(data) +
                "' on '" + std::string(mesh) + "'");
  wall_.set_pressure(values.col(0));
}

void TubeSolidAdapter::write(std::string_view mesh, std::string_view data,
                             Eigen::MatrixXd& values) {
  if (mesh != "nodes" || data != "cross_section_area")
    throw Error("tube1d-solid writes only 'cross_section_area' on mesh 'nodes', not '" +
                std::string(data) + "' on '" + std::string(mesh) + "'");
  values = wall_.area();
}

void TubeSolidAdapter::write_output(const OutputFrame& frame) {
  const std::string file = fmt::format("{}_wall_{:06d}.vtp", frame.prefix, frame.index);
  const Eigen::VectorXd radius = (wall_.area().array() / std::numbers::pi).sqrt();
  write_vtp(
      frame.vtk_directory / file, meshes_.front().mesh,
      {{"cross_section_area", wall_.area()}, {"radius", radius}, {"pressure", wall_.pressure()}},
      {}, nullptr, frame.vtk);
  files_ = {{"wall", file}};
}

void TubeSolidAdapter::write_restart(BinaryWriter& out) const {
  out.section("tube1d-solid");
  out.write(Eigen::VectorXd(wall_.pressure()));
  out.write(Eigen::VectorXd(wall_.area()));
  out.write(wall_.time());
}

void TubeSolidAdapter::read_restart(BinaryReader& in) {
  in.expect_section("tube1d-solid");
  Eigen::VectorXd p, a;
  double t = 0.0;
  in.read(p);
  in.read(a);
  in.read(t);
  if (p.size() != wall_.pressure().size() || a.size() != wall_.area().size())
    in.fail(std::to_string(wall_.area().size()) +
            " node values of the tube (same cells as the case)");
  wall_.set_state(p, a, t);
}

const MonitorTable<TubeSolidAdapter>& TubeSolidAdapter::monitor_table() {
  static const MonitorTable<TubeSolidAdapter> table = [] {
    using A = TubeSolidAdapter;
    MonitorTable<A> t;
    t.scalar("mid_area", "m^2", "cross-section area at the middle of the tube", [](const A& a) {
      const auto& area = a.wall_.area();
      return area(area.size() / 2);
    });
    t.scalar("max_area", "m^2", "largest cross-section area",
             [](const A& a) { return a.wall_.area().maxCoeff(); });
    return t;
  }();
  return table;
}

std::shared_ptr<const config::Spec> TubeSolidAdapter::spec() {
  static const auto s = tube_spec("tube1d-solid", "the elastic tube's wall: tube law a(p)", false);
  return s;
}

std::unique_ptr<Solver> TubeSolidAdapter::create(const SolverContext& context) {
  return std::make_unique<TubeSolidAdapter>(tube_parameters(context.config, false));
}

}  // namespace partita::adapters
