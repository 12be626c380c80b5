// The FE adapter's coupled nodal forces (as the double hull's nine cell interfaces): a "force" read on an
// interface is stored and handed to the solver with every other interface's forces once, before
// the step. The contract: the step sees the last values read on each interface, whatever the
// order and number of reads, every interface's at once (superposition); a read of the wrong size or
// with non-finite values is refused at the read, naming the mesh.
#include <catch2/catch.hpp>

#include <unistd.h>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>

#include "../support/adapter_solver.hpp"

using namespace partita;
namespace fs = std::filesystem;

namespace {

// An elastic block clamped at z = 0 with two interfaces: its top (zmax) and one side (xmax).
const char* kBlock = R"(
solver: fem
mesh: {box: {origin: [0, 0, 0], size: [0.1, 0.1, 0.1], cells: [2, 2, 2]}, element: hex8}
material: {youngs_modulus: 210 GPa, poisson_ratio: 0.3, density: 7850}
constraints: [{set: zmin, fix: [x, y, z]}]
interfaces: [{name: top, face: zmax}, {name: side, face: xmax}]
analysis: {type: static}
)";

Eigen::MatrixXd forces(std::size_t nodes, const Eigen::Vector3d& f) {
  Eigen::MatrixXd m(static_cast<Eigen::Index>(nodes), 3);
  for (Eigen::Index i = 0; i < m.rows(); ++i)  // a different force on every node
    m.row(i) = (f * (1.0 + 0.1 * static_cast<double>(i))).transpose();
  return m;
}

}  // namespace

TEST_CASE("fem adapter: the step sees the last force read on each interface, all of them",
          "[adapters][fem]") {
  const fs::path dir =
      fs::temp_directory_path() / ("partita_fem_coupled_forces_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  auto a = test::make_solver("fem", kBlock, dir, dir);
  auto b = test::make_solver("fem", kBlock, dir, dir);
  const std::size_t n_top = test::find_mesh(*a, "top").mesh.size();
  const std::size_t n_side = test::find_mesh(*a, "side").mesh.size();
  const Eigen::MatrixXd f1 = forces(n_top, {0.0, 0.0, 50.0});
  const Eigen::MatrixXd f2 = forces(n_top, {10.0, 0.0, -80.0});
  const Eigen::MatrixXd g = forces(n_side, {30.0, 5.0, 0.0});

  // a: top twice (the second read replaces the first), side between; b: only the last values
  a->read("top", "force", f1);
  a->read("side", "force", g);
  a->read("top", "force", f2);
  b->read("side", "force", g);
  b->read("top", "force", f2);
  a->advance(1.0);
  b->advance(1.0);
  Eigen::MatrixXd ua, ub;
  a->write("top", "displacement", ua);
  b->write("top", "displacement", ub);
  CHECK(ua.cwiseAbs().maxCoeff() > 0.0);
  CHECK((ua - ub).cwiseAbs().maxCoeff() == 0.0);  // the same sum in the same order: same bits

  // both interfaces act: linear elasticity superposes the top's and the side's loads applied alone
  auto c = test::make_solver("fem", kBlock, dir, dir);
  auto d = test::make_solver("fem", kBlock, dir, dir);
  c->read("top", "force", f2);
  d->read("side", "force", g);
  c->advance(1.0);
  d->advance(1.0);
  Eigen::MatrixXd uc, ud;
  c->write("top", "displacement", uc);
  d->write("top", "displacement", ud);
  CHECK(ud.cwiseAbs().maxCoeff() > 0.1 * uc.cwiseAbs().maxCoeff());  // the side's load shows
  CHECK((ua - uc - ud).cwiseAbs().maxCoeff() <= 1e-9 * ua.cwiseAbs().maxCoeff());
  CHECK(test::monitor_value(*a, "top.force_z") == Approx(f2.col(2).sum()).epsilon(1e-12));
  CHECK(test::monitor_value(*a, "side.force_x") == Approx(g.col(0).sum()).epsilon(1e-12));

  // a read of another size, or with a NaN, is refused at the read and names the mesh
  CHECK_THROWS_WITH(a->read("top", "force", forces(n_top + 1, {1.0, 0.0, 0.0})),
                    Catch::Contains("'top'") && Catch::Contains("rows of 3"));
  Eigen::MatrixXd bad = f2;
  bad(0, 1) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(a->read("side", "force", bad.topRows(static_cast<Eigen::Index>(n_side))),
                    Catch::Contains("non-finite") && Catch::Contains("'side'"));
  fs::remove_all(dir);
}

// An implicit scheme restores the checkpoint and reads again; a step between a restore and the
// next read (or a monitor, or the audit) must see the loads the checkpoint held, not the last
// values read before the restore (the solver's loads come back with its state; the adapter's
// copies of what was read, which the audit and the force monitors use, must come back too).
TEST_CASE("fem adapter: a restored checkpoint brings back the forces read before it",
          "[adapters][fem]") {
  const fs::path dir =
      fs::temp_directory_path() / ("partita_fem_restored_forces_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const char* dynamic = R"(
solver: fem
mesh: {box: {origin: [0, 0, 0], size: [0.1, 0.1, 0.1], cells: [2, 2, 2]}, element: hex8}
material: {youngs_modulus: 210 GPa, poisson_ratio: 0.3, density: 7850}
constraints: [{set: zmin, fix: [x, y, z]}]
interfaces: [{name: top, face: zmax}]
analysis: {type: transient}
)";
  auto a = test::make_solver("fem", dynamic, dir, dir);
  auto b = test::make_solver("fem", dynamic, dir, dir);
  const std::size_t n = test::find_mesh(*a, "top").mesh.size();
  const Eigen::MatrixXd f1 = forces(n, {0.0, 0.0, -4.0e5});
  const Eigen::MatrixXd f2 = forces(n, {3.0e5, 0.0, 9.0e5});
  // a: f1, one step, checkpoint, f2 read, restored, two steps; b: f1 and the same three steps
  a->read("top", "force", f1);
  b->read("top", "force", f1);
  a->advance(1e-5);
  b->advance(1e-5);
  a->save_checkpoint();
  a->read("top", "force", f2);
  a->restore_checkpoint();
  for (int k = 0; k < 2; ++k) {
    a->advance(1e-5);
    b->advance(1e-5);
  }
  Eigen::MatrixXd ua, ub;
  a->write("top", "displacement", ua);
  b->write("top", "displacement", ub);
  CHECK(ua.cwiseAbs().maxCoeff() > 0.0);
  CHECK((ua - ub).cwiseAbs().maxCoeff() == 0.0);
  // the loads' work on the displacements (the interface audit) and the force monitor are b's
  const double wb = b->interface_work("top").value();
  CHECK(wb != 0.0);
  CHECK(a->interface_work("top").value() == wb);
  CHECK(test::monitor_value(*a, "top.force_z") == Approx(f1.col(2).sum()).epsilon(1e-12));
  fs::remove_all(dir);
}
