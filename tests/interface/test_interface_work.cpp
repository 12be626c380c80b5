// InterfaceWork, the interface-work audit of one coupling mesh: the trapezoid of f . dx against
// the work of a constant force over a known displacement (and of a linearly growing one), a
// checkpoint-restore round trip, and the restart layout read back.
#include <catch2/catch.hpp>

#include <sstream>

#include "partita/interface/binary_io.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/interface_work.hpp"

using partita::InterfaceWork;

namespace {

// Two points, each pushed by the bodies with f = (0, 0, -F) (a granular bed on a lid).
Eigen::MatrixX3d constant_force(double F) {
  Eigen::MatrixX3d f(2, 3);
  f << 0, 0, -F, 0, 0, -F;
  return f;
}

Eigen::MatrixX3d lifted(const Eigen::MatrixX3d& x, double dz) {
  Eigen::MatrixX3d y = x;
  y.col(2).array() += dz;
  return y;
}

}  // namespace

TEST_CASE("a moving mesh does -f . dx on the bodies: a constant force over a known lift",
          "[interface][interface_work]") {
  const double F = 3.0, lift = 0.02;
  Eigen::MatrixX3d x(2, 3);
  x << 0, 0, 0, 1, 0, 0;
  InterfaceWork audit = InterfaceWork::motion(x, constant_force(F));
  CHECK(audit.work() == 0.0);
  // lifting both points by `lift` in 4 steps against the bodies' push: the mesh does 2 F lift
  for (int k = 1; k <= 4; ++k) audit.motion_step(lifted(x, lift * k / 4.0), constant_force(F));
  CHECK(audit.work() == Approx(2.0 * F * lift).epsilon(1e-14));
}

TEST_CASE("the trapezoid is exact for a force growing linearly with the displacement",
          "[interface][interface_work]") {
  // a spring of stiffness k under one node pushed by du: W = 1/2 k u^2, exact for the trapezoid
  const double k = 250.0, u_end = 0.004;
  const int steps = 7;
  InterfaceWork audit = InterfaceWork::loads();
  const std::vector<std::size_t> nodes = {1};  // the second node of a two-node model
  Eigen::VectorXd du = Eigen::VectorXd::Zero(6);
  Eigen::MatrixX3d f(1, 3);
  for (int s = 1; s <= steps; ++s) {
    const double u = u_end * s / steps;
    du(4) = u_end / steps;  // node 1, y
    f << 0.0, k * u, 0.0;
    audit.load_step(du, nullptr, [](const Eigen::MatrixX3d&) { return 0.0; }, nodes, &f);
  }
  // the first step has no earlier load: half of its end's, as a load that was zero before
  CHECK(audit.work() == Approx(0.5 * k * u_end * u_end).epsilon(1e-12));
}

TEST_CASE("tractions' work comes from the solver's rule, the last step's and this step's",
          "[interface][interface_work]") {
  InterfaceWork audit = InterfaceWork::loads();
  Eigen::MatrixX3d t(3, 3);
  t.setConstant(2.0);
  const Eigen::VectorXd du = Eigen::VectorXd::Constant(3, 0.5);
  // a rule that integrates t . du over a face of area 1: the sum of t's first column times 0.5
  auto rule = [&](const Eigen::MatrixX3d& tt) { return tt.col(0).sum() * du(0); };
  audit.load_step(du, &t, rule, {}, nullptr);
  CHECK(audit.work() == Approx(0.5 * 3.0));  // only this step's load: 1/2 (3 x 2 x 0.5)
  audit.load_step(du, &t, rule, {}, nullptr);
  CHECK(audit.work() == Approx(1.5 + 3.0));  // 1/2 (3 + 3)
}

TEST_CASE("a checkpoint restores the audit bit for bit", "[interface][interface_work]") {
  Eigen::MatrixX3d x(2, 3);
  x << 0, 0, 0, 1, 0, 0;
  InterfaceWork audit = InterfaceWork::motion(x, constant_force(1.0));
  audit.motion_step(lifted(x, 0.01), constant_force(1.5));
  audit.save_checkpoint();
  const double saved = audit.work();
  audit.motion_step(lifted(x, 0.03), constant_force(4.0));
  const double once = audit.work();
  CHECK(once != saved);
  audit.restore_checkpoint();
  CHECK(audit.work() == saved);
  // the step repeated from the checkpoint gives the same bits (the last step's arrays came back)
  audit.motion_step(lifted(x, 0.03), constant_force(4.0));
  CHECK(audit.work() == once);
}

TEST_CASE("the restart layout: the work, then the last step's arrays; a wrong size is refused",
          "[interface][interface_work]") {
  Eigen::MatrixX3d x(2, 3);
  x << 0, 0, 0, 1, 0, 0;
  InterfaceWork audit = InterfaceWork::motion(x, constant_force(1.0));
  audit.motion_step(lifted(x, 0.01), constant_force(2.0));
  std::ostringstream bytes;
  partita::BinaryWriter out(bytes);
  audit.save(out);
  {  // the layout: a double, then two matrices (rows, cols, values)
    std::ostringstream plain;
    partita::BinaryWriter w(plain);
    w.write(audit.work());
    w.write(Eigen::MatrixXd(lifted(x, 0.01)));
    w.write(Eigen::MatrixXd(constant_force(2.0)));
    CHECK(plain.str() == bytes.str());
  }
  std::istringstream in(bytes.str());
  partita::BinaryReader reader(in, "test");
  InterfaceWork back = InterfaceWork::motion(x, constant_force(0.0));
  back.load(reader, "vertices of mesh 'lid'");
  CHECK(back.work() == audit.work());
  back.motion_step(lifted(x, 0.02), constant_force(2.0));
  audit.motion_step(lifted(x, 0.02), constant_force(2.0));
  CHECK(back.work() == audit.work());
  // a mesh of three points cannot take the state of two
  Eigen::MatrixX3d three(3, 3);
  three.setZero();
  InterfaceWork other = InterfaceWork::motion(three, three);
  std::istringstream in2(bytes.str());
  partita::BinaryReader reader2(in2, "test");
  CHECK_THROWS_WITH(other.load(reader2, "vertices of mesh 'lid'"),
                    Catch::Contains("3 vertices of mesh 'lid'"));
}
