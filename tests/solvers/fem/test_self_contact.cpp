// Single-surface (self) contact of an FE body: two blocks of one mesh that meet exchange their
// momentum as an elastic impact does, and do not pass through each other
// (without the contact they do); a thinned plate is no contact with itself; the faces an
// eroded element leaves behind push each other apart with the penalty's spring energy; a
// restart gives the same bits.
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>

#include "partita/fem/block_assembler.hpp"
#include "partita/fem/box_mesher.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/self_contact.hpp"
#include "partita/fem/structural_solver.hpp"

using namespace partita::fem;

namespace {

const char* const kSides[] = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};

// Appends a box mesh to `into` (nodes, elements, its six faces into the face `surface`, node
// set `set` of all its nodes); returns its node offset.
std::size_t append_box(Mesh& into, const BoxSpec& spec, const std::string& set) {
  const Mesh box = make_box_mesh(spec);
  const std::size_t offset = into.num_nodes();
  std::vector<std::size_t> all;
  for (std::size_t i = 0; i < box.num_nodes(); ++i) all.push_back(into.add_node(box.node(i)));
  for (const auto& e : box.elements()) {
    std::vector<std::size_t> nodes;
    for (auto n : e.node_span()) nodes.push_back(n + offset);
    into.add_element(e.type, nodes);
  }
  for (const char* side : kSides)
    for (const auto& s : box.face(side)) {
      std::vector<std::size_t> nodes;
      for (auto n : s.node_span()) nodes.push_back(n + offset);
      into.add_face_element("surface", s.type, nodes);
      into.add_face_element(set + "_" + side, s.type, nodes);
    }
  into.add_node_set(set, all);
  return offset;
}

// A column of three 10 mm steel cubes (1 x 1 x 3 Hex8) with the faces between elements, its
// middle cube the one that erodes, and u with the top cube moved down by `by`.
struct Column {
  static constexpr double h = 0.01;
  Model model;
  BlockAssembler assembler;
  Column() : model(mesh(), Material{210e9, 0.3, 7850}), assembler(model.mesh()) {}
  static Mesh mesh() {
    BoxSpec b;
    b.size = Vec3(h, h, 3 * h);
    b.cells = {1, 1, 3};
    Mesh m = make_box_mesh(b);
    m.add_interior_faces("between");
    return m;
  }
  bool middle(std::size_t el) const {
    double z = 0.0;
    for (auto node : model.mesh().element(el).node_span()) z += model.mesh().node(node).z();
    return std::abs(z / 8.0 - 1.5 * h) < 1e-9;
  }
  Eigen::VectorXd top_down(double by) const {
    Eigen::VectorXd u = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(3 * model.mesh().num_nodes()));
    for (std::size_t i = 0; i < model.mesh().num_nodes(); ++i)
      if (model.mesh().node(i).z() > 1.5 * h) u[3 * static_cast<Eigen::Index>(i) + 2] = -by;
    return u;
  }
};

}  // namespace

TEST_CASE("self contact: two blocks of one mesh meet as an elastic impact",
          "[fem][contact][self]") {
  // two steel cubes of 10 mm (2 x 2 x 2 Hex8 each), one above the other 0.05 mm apart; the lower
  // one moves up at 5 m/s
  const double side = 0.01, gap = 5e-5, v0 = 5.0, rho = 7850;
  // the lower cube 6 mm (2 x 2 x 2 Hex8), off the upper one's axis by 1 mm; the upper 10 mm (3 x
  // 3 x 3): the nodes of each meet the other's faces between its nodes
  const double small = 0.006;
  Mesh mesh;
  BoxSpec b;
  b.origin = Vec3(0.003, 0.003, side - small);
  b.size = Vec3(small, small, small);
  b.cells = {2, 2, 2};
  append_box(mesh, b, "a");
  b.origin = Vec3(0, 0, side + gap);
  b.size = Vec3(side, side, side);
  b.cells = {3, 3, 3};
  append_box(mesh, b, "b");
  const std::vector<std::size_t> a_nodes = mesh.node_set("a"), b_nodes = mesh.node_set("b");
  // lumped masses: each Hex8 gives each of its nodes rho V / 8
  Eigen::VectorXd nodal_mass = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(mesh.num_nodes()));
  for (const auto& el : mesh.elements()) {
    const Vec3 d = mesh.node(el.nodes[6]) - mesh.node(el.nodes[0]);
    for (auto nd : el.node_span()) nodal_mass[static_cast<Eigen::Index>(nd)] += rho * d.prod() / 8;
  }
  const double ma = rho * small * small * small, mb = rho * side * side * side;
  const bool with_contact = GENERATE(true, false);
  INFO("self contact " << with_contact);
  SolverOptions o;
  o.nonlinear_path = true;
  o.mass = MassType::Lumped;
  o.integrator = Integrator::CentralDifference;
  StructuralSolver s(Model(mesh, Material{210e9, 0.3, rho}), o);
  SelfContact* contact = nullptr;
  if (with_contact) {
    auto c = std::make_unique<SelfContact>("self", s.model(), std::vector<std::string>{"surface"});
    contact = c.get();
    s.add_contribution(std::move(c));
  }
  SolverState start = s.save_state();
  for (auto n : a_nodes) start.velocity[3 * static_cast<Eigen::Index>(n) + 2] = v0;
  s.restore_state(start);
  const double dt = 0.9 * s.stable_time_step();
  const auto velocity = [&](const std::vector<std::size_t>& nodes) {  // of the centre of mass
    double p = 0.0, m = 0.0;
    for (auto n : nodes) {
      p += nodal_mass[static_cast<Eigen::Index>(n)] * s.velocity()[3 * static_cast<Eigen::Index>(n) + 2];
      m += nodal_mass[static_cast<Eigen::Index>(n)];
    }
    return p / m;
  };
  const double e0 = 0.5 * ma * v0 * v0;
  // the time an elastic wave takes through the upper block and back, times a few
  const double wave = 2.0 * side / std::sqrt(210e9 / rho);
  double deepest = 0.0, max_energy_error = 0.0, max_momentum_error = 0.0;
  std::size_t in_contact = 0;
  SolverState mid;
  const double t_end = 8.0 * wave + gap / v0;
  while (s.time() < t_end) {
    s.step(dt);
    // the lower block's top nodes against the upper block's lowest bottom node (an over-estimate
    // of the overlap where the bottom is dented)
    double top = -1.0, bottom = 1.0;
    for (auto n : a_nodes) top = std::max(top, (mesh.node(n) + s.displacement(n)).z());
    for (auto n : b_nodes) bottom = std::min(bottom, (mesh.node(n) + s.displacement(n)).z());
    deepest = std::max(deepest, top - bottom);
    const double momentum = ma * velocity(a_nodes) + mb * velocity(b_nodes);
    max_momentum_error = std::max(max_momentum_error, std::abs(momentum - ma * v0));
    if (s.time() > 2 * dt)  // the kinetic energy needs the first step's mass
      max_energy_error = std::max(max_energy_error, std::abs(s.kinetic_energy() + s.strain_energy() - e0));
    if (contact != nullptr && contact->active_nodes() > 0 && ++in_contact == 10) mid = s.save_state();
  }
  const double va = velocity(a_nodes), vb = velocity(b_nodes);
  WARN("self contact " << with_contact << ": deepest overlap " << deepest * 1e6 << " um, v_a "
                       << va << ", v_b " << vb << " m/s, max |dE|/E0 " << max_energy_error / e0);
  if (!with_contact) {
    // nothing stops the lower block: it passes into the upper one
    CHECK(deepest > 0.5 * (v0 * t_end - gap));
    CHECK(va == Approx(v0));
    CHECK(vb == Approx(0.0).margin(1e-9));
    return;
  }
  // an elastic impact of a 6 mm cube on a 10 mm one (masses ma, mb): the striker leaves with
  // (ma - mb)/(ma + mb) v0, the struck with 2 ma/(ma + mb) v0; the blocks keep part of the
  // energy as vibration, so the restitution (vb - va)/v0 lies a little below 1
  const double restitution = (vb - va) / v0;
  CHECK(restitution > 0.6);
  CHECK(restitution < 1.02);
  CHECK(va < 0.0);  // the lighter striker rebounds
  CHECK(vb == Approx(2 * ma / (ma + mb) * v0 * (1 + restitution) / 2).epsilon(0.05));
  // the forces are equal and opposite: momentum to round-off; energy to the penalty's accuracy
  CHECK(max_momentum_error < 1e-9 * ma * v0);
  CHECK(max_energy_error < 0.03 * e0);
  // the penalty stops the block within a fraction of an element's depth
  CHECK(deepest < 0.25 * 0.003);
  CHECK(in_contact >= 10);
  // a restart inside the contact steps to the same bits
  const SolverState end = s.save_state();
  s.restore_state(mid);
  while (s.time() < end.time - 0.5 * dt) s.step(dt);
  CHECK(s.displacement() == end.displacement);
  CHECK(s.velocity() == end.velocity);
}

TEST_CASE("self contact: a plate thinned to 40 % is no contact with its own far side",
          "[fem][contact][self]") {
  // one and two elements through the thickness: the far side's nodes lie deeper than the depth
  // (0.5 h) behind a face, or belong to the face's own element
  const int layers = GENERATE(1, 2);
  BoxSpec b;
  b.size = Vec3(0.04, 0.04, 0.004);
  b.cells = {4, 4, layers};
  Mesh mesh = make_box_mesh(b);
  mesh.add_interior_faces("between");
  const Model model(mesh, Material{210e9, 0.3, 7850});
  SelfContact c("self", model, {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax", "between"});
  CHECK(c.triangles_in_contact_surface() == 2 * (2 * 16 + 4 * 4 * static_cast<std::size_t>(layers)));
  const BlockAssembler assembler(model.mesh());
  const auto n = static_cast<Eigen::Index>(3 * model.mesh().num_nodes());
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n), f = Eigen::VectorXd::Zero(n);
  for (std::size_t i = 0; i < model.mesh().num_nodes(); ++i)
    u[3 * static_cast<Eigen::Index>(i) + 2] = -0.6 * model.mesh().node(i).z();  // thinned to 40 %
  c.set_time(0.0, 0.0);
  c.add(u, f, nullptr, assembler);
  CHECK(c.active_nodes() == 0);
  CHECK(f.norm() == 0.0);
  CHECK(c.stored_energy() == 0.0);
}

TEST_CASE("self contact: the faces an eroded element exposes push each other apart",
          "[fem][contact][self][rupture]") {
  // a column of three 10 mm steel cubes; the middle one erodes while the top one has come down
  // onto the bottom one (the middle crushed flat), then the top one goes on down until its bottom
  // face lies 1 mm below the bottom cube's top face
  const double e = 210e9, h = Column::h, factor = 0.1, pass = 1e-3;
  const Column col;
  const Model& model = col.model;
  const BlockAssembler& assembler = col.assembler;
  const auto n = static_cast<Eigen::Index>(3 * model.mesh().num_nodes());
  const auto middle = [&](std::size_t el) { return col.middle(el); };
  const auto top_down = [&](double by) { return col.top_down(by); };
  SelfContact c("self", model, {"zmin", "zmax", "between"}, {factor, 0.5});
  Eigen::VectorXd f = Eigen::VectorXd::Zero(n);
  c.set_time(0.0, 0.0);
  c.add(top_down(h + pass), f, nullptr, assembler);
  CHECK(c.active_nodes() == 0);  // the middle element is there: its faces are inside the body
  // it erodes with the faces touching (a refresh at the committed configuration)
  c.set_eroded(middle);
  c.set_time(0.0, 0.0);
  c.add(top_down(h), f, nullptr, assembler);
  CHECK(c.active_nodes() == 0);
  // a step on: each of the 8 nodes of the two faces lies behind the other face by 1 mm
  f.setZero();
  c.set_time(1e-6, 1.0);
  c.add(top_down(h + pass), f, nullptr, assembler);
  c.commit();
  CHECK(c.active_nodes() == 8);
  // k per node = factor E (A / 4) / h (the node's one exposed face); W = 8 * 1/2 k g^2
  const double k = factor * e * (h * h / 4) / h;
  CHECK(c.stored_energy() == Approx(8 * 0.5 * k * pass * pass));
  // f is the internal force: -f the contact force on the nodes; the top cube is pushed up, the
  // bottom one down, each by 8 k g (its 4 nodes' own springs and its corners' share of the
  // other side's), and the sum is zero
  double up = 0.0, down = 0.0;
  for (std::size_t i = 0; i < model.mesh().num_nodes(); ++i) {
    const double fz = -f[3 * static_cast<Eigen::Index>(i) + 2];
    if (model.mesh().node(i).z() > 1.5 * h)
      up += fz;
    else
      down += fz;
    CHECK(std::abs(f[3 * static_cast<Eigen::Index>(i)]) < 1e-9 * k * pass);  // normal to the faces
  }
  CHECK(up == Approx(8 * k * pass));
  CHECK(down == Approx(-8 * k * pass));
  // 4.5 mm through: still caught (depth 0.5 h = 5 mm), the springs' energy as g^2
  f.setZero();
  c.add(top_down(h + 4.5e-3), f, nullptr, assembler);
  CHECK(c.active_nodes() == 8);
  CHECK(c.stored_energy() == Approx(8 * 0.5 * k * 4.5e-3 * 4.5e-3));
  // the committed state (1 mm through) restored: the same contact, the same energy
  const std::vector<double> state = c.committed_state();
  SelfContact again("self", model, {"zmin", "zmax", "between"}, {factor, 0.5});
  again.set_eroded(middle);
  again.set_committed_state(state);
  f.setZero();
  again.add(top_down(h + pass), f, nullptr, assembler);
  CHECK(again.active_nodes() == 8);
  CHECK(again.stored_energy() == Approx(8 * 0.5 * k * pass * pass));
}

TEST_CASE("self contact: a face that erosion exposes behind a node pushes only beyond that depth",
          "[fem][contact][self][rupture]") {
  // the column above, the middle element eroding when the top cube is already 1 mm through (a
  // crushed element): the new faces find the nodes 1 mm behind them and store nothing; 0.5 mm
  // further the springs hold 0.5 mm; back out, the depth follows the nodes down
  const double e = 210e9, h = Column::h, factor = 0.1, pass = 1e-3;
  const Column col;
  const Model& model = col.model;
  const BlockAssembler& assembler = col.assembler;
  const auto n = static_cast<Eigen::Index>(3 * model.mesh().num_nodes());
  const auto top_down = [&](double by) { return col.top_down(by); };
  SelfContact c("self", model, {"zmin", "zmax", "between"}, {factor, 0.5});
  c.set_eroded([&](std::size_t el) { return col.middle(el); });
  Eigen::VectorXd f = Eigen::VectorXd::Zero(n);
  c.set_time(0.0, 0.0);
  c.add(top_down(h + pass), f, nullptr, assembler);
  CHECK(c.stored_energy() == 0.0);
  CHECK(f.norm() == 0.0);
  const double k = factor * e * (h * h / 4) / h;
  c.set_time(1e-6, 1.0);
  c.add(top_down(h + 1.5 * pass), f, nullptr, assembler);
  c.commit();
  CHECK(c.active_nodes() == 8);
  CHECK(c.stored_energy() == Approx(8 * 0.5 * k * 0.25 * pass * pass));
  // out to 0.5 mm through: no force (the pre-penetration is 1 mm), and it follows to 0.5 mm
  c.add(top_down(h + 0.5 * pass), f, nullptr, assembler);
  c.commit();
  CHECK(c.active_nodes() == 0);
  f.setZero();
  c.add(top_down(h + 0.75 * pass), f, nullptr, assembler);
  CHECK(c.active_nodes() == 8);
  CHECK(c.stored_energy() == Approx(8 * 0.5 * k * 0.0625 * pass * pass));
}

TEST_CASE("self contact: bad options and faces are named", "[fem][contact][self]") {
  BoxSpec b;
  b.cells = {1, 1, 1};
  const Model model(make_box_mesh(b), Material{210e9, 0.3, 7850});
  CHECK_THROWS_WITH(SelfContact("s", model, {"top"}), Catch::Contains("top"));
  CHECK_THROWS_WITH(SelfContact("s", model, {}), Catch::Contains("no face"));
  CHECK_THROWS_WITH(SelfContact("s", model, {"zmax", "zmax"}), Catch::Contains("named twice"));
  CHECK_THROWS_WITH(SelfContact("s", model, {"zmax"}, {0.1, 1.0}), Catch::Contains("0 < depth < 1"));
  CHECK_THROWS_WITH(SelfContact("s", model, {"zmax"}, {-1.0, 0.5}), Catch::Contains("penalty factor"));
}

TEST_CASE("self contact: a node that comes back within the caught depth from deeper is not pushed "
          "out with a depth it did not make",
          "[fem][contact][self][rupture]") {
  // the column, its middle element eroded before the start (the two faces 10 mm apart), caught
  // to 0.4 h = 4 mm; the top cube passes 4.5 mm through the bottom one in a step (beyond the
  // catch, and 5.5 mm from the far faces: no contact), then comes back to 3.5 mm through: its
  // nodes meet the face 3.5 mm behind it, a depth their motion made away from it. The contact
  // holds it as a pre-penetration (1/2 k g^2 of 3.5 mm pushed out would be 8 x 322 J); going
  // back in to 3.9 mm, the springs hold the 0.4 mm. An approach from in front is pushed with its
  // whole depth, as before.
  const double e = 210e9, h = Column::h, factor = 0.1, mm = 1e-3;
  const Column col;
  const Model& model = col.model;
  const BlockAssembler& assembler = col.assembler;
  const auto n = static_cast<Eigen::Index>(3 * model.mesh().num_nodes());
  const auto top_down = [&](double by) { return col.top_down(by); };
  const double k = factor * e * (h * h / 4) / h;
  SelfContact c("self", model, {"zmin", "zmax", "between"}, {factor, 0.4});
  c.set_eroded([&](std::size_t el) { return col.middle(el); });
  Eigen::VectorXd f = Eigen::VectorXd::Zero(n);
  c.set_time(0.0, 0.0);
  c.add(top_down(0.0), f, nullptr, assembler);
  CHECK(c.active_nodes() == 0);
  c.set_time(1e-6, 1.0);
  c.add(top_down(h + 4.5 * mm), f, nullptr, assembler);
  c.commit();
  CHECK(c.active_nodes() == 0);  // deeper than 0.4 h
  f.setZero();
  c.add(top_down(h + 3.5 * mm), f, nullptr, assembler);
  c.commit();
  INFO("energy at 3.5 mm on the way out " << c.stored_energy() << " J (1/2 k g^2 x 8 = "
                                          << 8 * 0.5 * k * 3.5 * mm * 3.5 * mm << " J)");
  CHECK(c.active_nodes() == 0);
  CHECK(c.stored_energy() == 0.0);
  CHECK(f.norm() == 0.0);
  f.setZero();
  c.add(top_down(h + 3.9 * mm), f, nullptr, assembler);
  CHECK(c.active_nodes() == 8);
  CHECK(c.stored_energy() == Approx(8 * 0.5 * k * 0.4 * mm * 0.4 * mm).epsilon(1e-6));
  // the state committed at 3.5 mm restored: the same pre-penetration, the same springs
  const std::vector<double> state = c.committed_state();
  SelfContact again("self", model, {"zmin", "zmax", "between"}, {factor, 0.4});
  again.set_eroded([&](std::size_t el) { return col.middle(el); });
  again.set_committed_state(state);
  again.add(top_down(h + 3.5 * mm), f, nullptr, assembler);
  CHECK(again.stored_energy() == 0.0);
  again.set_time(2e-6, 1.0);
  again.add(top_down(h + 3.9 * mm), f, nullptr, assembler);
  CHECK(again.stored_energy() == Approx(c.stored_energy()).epsilon(1e-12));

  // from in front: 1 mm through in one step is its own approach, pushed with 1 mm
  SelfContact front("self", model, {"zmin", "zmax", "between"}, {factor, 0.4});
  front.set_eroded([&](std::size_t el) { return col.middle(el); });
  front.set_time(0.0, 0.0);
  front.add(top_down(0.0), f, nullptr, assembler);
  front.set_time(1e-6, 1.0);
  front.add(top_down(h + 1 * mm), f, nullptr, assembler);
  CHECK(front.active_nodes() == 8);
  CHECK(front.stored_energy() == Approx(8 * 0.5 * k * mm * mm));
}

TEST_CASE("self contact: a node passed on to a deeper face keeps its spring's overlap",
          "[fem][contact][self][rupture]") {
  // three 10 mm blocks of one mesh: b1 below z = 0, b2 in the same place raised 2 mm, t (2 mm
  // across) above them. t comes down 2 mm in a step, from 1 mm above to 1 mm into b1's top face
  // (it is 3 mm behind b2's, which b1's lies in front of: b1's face is the nearest): its four
  // bottom nodes' springs hold 1 mm, and its four top nodes', 1 mm into b2's top face, too. Then
  // b1 erodes: the bottom nodes pass on to b2's top face, 3 mm deep. The springs keep their 1 mm
  // (pushed with 3 mm the bottom ones would store 9 times the energy).
  const double h = 0.01, mm = 1e-3;
  Mesh mesh;
  BoxSpec b;
  b.origin = Vec3(0, 0, -h);
  b.size = Vec3(h, h, h);
  append_box(mesh, b, "b1");
  b.origin = Vec3(0, 0, -h + 2 * mm);
  append_box(mesh, b, "b2");
  b.origin = Vec3(4 * mm, 4 * mm, 1 * mm);
  b.size = Vec3(2 * mm, 2 * mm, 2 * mm);
  append_box(mesh, b, "t");
  const Model model(mesh, Material{210e9, 0.3, 7850});
  const BlockAssembler assembler(model.mesh());
  const auto n = static_cast<Eigen::Index>(3 * model.mesh().num_nodes());
  const std::vector<std::size_t> t_nodes = model.mesh().node_set("t");
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n), f = Eigen::VectorXd::Zero(n);
  SelfContact c("self", model, {"surface"});
  c.set_time(0.0, 0.0);
  c.add(u, f, nullptr, assembler);
  c.commit();
  for (auto node : t_nodes) u[3 * static_cast<Eigen::Index>(node) + 2] = -2 * mm;
  c.set_time(1e-6, 1.0);
  c.add(u, f, nullptr, assembler);
  c.commit();
  const double held = c.stored_energy();
  CHECK(c.active_nodes() == 8);
  CHECK(held > 0.0);
  c.set_eroded([](std::size_t el) { return el == 0; });  // b1
  c.set_time(1e-6, 0.0);
  f.setZero();
  c.add(u, f, nullptr, assembler);
  INFO("springs' energy with b1's face " << held << " J, passed on to b2's " << c.stored_energy()
                                         << " J");
  CHECK(c.active_nodes() == 8);
  CHECK(c.stored_energy() == Approx(held).epsilon(1e-9));
}
