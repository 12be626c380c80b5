#include "indenter_config.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <limits>

#include "partita/fem/capsule_shape.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/plane_shape.hpp"
#include "partita/fem/sphere_shape.hpp"
#include "partita/fem/triangulated_shape.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/output.hpp"
#include "partita/interface/stl.hpp"

namespace partita::adapters {

using config::Node;
using config::Spec;

std::shared_ptr<Spec> indenter_spec() {
  auto penalty = std::make_shared<Spec>(
      "penalty", "penalty stiffness of the node-to-surface contact");
  penalty
      ->real("factor",
             "k_n = factor E A_node / h per face node (A_node its share of the face's area, h = "
             "V_e / A_f the element's depth under the face: a spring as stiff as the element "
             "under the node); 1: penetration about the element's own deformation, 10-100: that "
             "much less, at a proportionally smaller stable step")
      .positive()
      .def(1.0);
  penalty->real("tangential_factor", "friction: stick stiffness k_t = this * k_n").positive().def(1.0);

  auto motion = std::make_shared<Spec>(
      "motion", "driven (velocity or table, no mass) or free (mass, velocity, gravity)");
  motion->reals("velocity", "driven: its constant velocity; free: its initial velocity")
      .unit("m/s")
      .size(3);
  motion->any("table",
              "driven: the velocity over time, [[t, vx, vy, vz], ...] (linear between rows, held "
              "before the first and after the last; integrated exactly)");
  motion->real("mass", "free: the indenter's mass (moves under the contact force, gravity and the "
                       "resultant of the forces an exchange gives its mesh <name> (data force: "
                       "granules it pushes); analysis.integrator: central-difference)")
      .unit("kg")
      .positive();
  motion->reals("gravity", "free: gravitational acceleration on the indenter").unit("m/s^2").size(3).def(std::vector<double>{0.0, 0.0, 0.0});

  auto s = std::make_shared<Spec>(
      "indenter",
      "a rigid body that translates and touches the nodes of an FE face (penalty contact)");
  s->string("name", "monitors <name>.x, .vx, .force_x, .penetration, .work, .kinetic_energy, .contact_energy, "
                    ".friction_work ... (free: .external_force_x, .external_work); the moving mesh "
                    "<name> (sphere, capsule, surface): writes displacement, reads force when free")
      .required();
  s->choice("shape",
            "sphere (radius), capsule (radius, length, axis: a cylinder with hemispherical ends, "
            "a bulbous bow), plane (a half-space: position on its boundary, normal pointing out "
            "of the rigid body, towards the structure) or surface (a closed STL, outward normals)",
            {"sphere", "capsule", "plane", "surface"})
      .required();
  s->reals("position",
           "sphere and capsule: the centre; plane: a point of its boundary; surface: the "
           "translation applied to the STL (default 0)")
      .unit("m")
      .size(3);
  s->real("radius", "sphere, capsule: radius").unit("m").positive();
  s->real("length", "capsule: length of the cylindrical part between the caps' centres")
      .unit("m")
      .non_negative();
  s->reals("axis", "capsule: direction of its axis").size(3);
  s->reals("normal", "plane: outward normal of the rigid half-space").size(3);
  s->string("stl", "surface: closed STL file, relative to the case file");
  s->real("scale", "surface: factor applied to the STL coordinates").positive().def(1.0);
  s->real("search_radius",
          "surface: how far from the surface points are searched (penetrations deeper than this "
          "are missed; default: the contact face's mean element size)")
      .unit("m")
      .positive();
  s->strings("face",
             "the FE face whose nodes it touches, or a list of faces (their union: e.g. [outer, "
             "cell_1_1], the struck face and the cavity behind it, for a body that breaks through)")
      .required();
  s->section("penalty", "penalty stiffness", penalty);
  s->real("friction", "Coulomb friction coefficient (0: frictionless)").non_negative().def(0.0);
  s->section("motion", "how it moves", motion).required();
  return s;
}

namespace {

void require_keys(const Node& n, const std::string& shape, std::initializer_list<const char*> keys) {
  for (const char* k : keys)
    if (!n.has(k)) n.fail(fmt::format("shape {} needs '{}'", shape, k));
}

void forbid_keys(const Node& n, const std::string& shape, std::initializer_list<const char*> keys) {
  for (const char* k : keys)
    if (n.has(k)) n[k].fail(fmt::format("'{}' does not apply to shape {}", k, shape));
}

double mean_face_size(const fem::Mesh& mesh, const std::vector<std::string>& faces) {
  double sum = 0.0;
  std::size_t count = 0;
  for (const std::string& face : faces)
    for (const auto& e : mesh.face(face)) {
      const auto corners = static_cast<std::size_t>(fem::corner_count(e.type));
      for (std::size_t k = 0; k < corners; ++k)
        sum += (mesh.node(e.nodes[k]) - mesh.node(e.nodes[(k + 1) % corners])).norm() /
               static_cast<double>(corners);
      ++count;
    }
  return count == 0 ? 1.0 : sum / static_cast<double>(count);
}

fem::VelocityTable velocity_table(const Node& table) {
  if (!table.is_sequence() || table.items().empty())
    table.fail("a velocity table is a list of rows [t, vx, vy, vz]");
  std::vector<std::pair<double, fem::Vec3>> rows;
  for (const Node& row : table.items()) {
    const std::vector<double> r = row.as_reals();
    if (r.size() != 4) row.fail(fmt::format("a row of the velocity table is [t, vx, vy, vz]; this one has {} numbers", r.size()));
    rows.emplace_back(r[0], fem::Vec3(r[1], r[2], r[3]));
  }
  try {
    return fem::VelocityTable(std::move(rows));
  } catch (const fem::Error& e) {
    table.fail(e.what());
  }
}

std::string vec(const fem::Vec3& v) { return fmt::format("({:.4g}, {:.4g}, {:.4g})", v.x(), v.y(), v.z()); }

// A rigid body placed inside the structure is refused at set-up: its first evaluation would put
// k_n times the overlap on the nodes inside (the usual cause: a length without its unit, read in
// metres). Allowed: touching, i.e. a node inside by at most round-off of the face's size.
void refuse_start_inside(const Node& n, const std::string& name, const std::string& shape,
                         const std::vector<std::string>& faces, const fem::Model& model,
                         const fem::IndenterContact& contact) {
  const fem::IndenterContact::DeepestNode deepest = contact.deepest_node();
  const double element = mean_face_size(model.mesh(), faces);
  if (!(deepest.depth > 1e-6 * element)) return;
  std::string face = faces.front();
  for (const std::string& f : faces) {
    const auto nodes = model.mesh().face_nodes(f);
    if (std::find(nodes.begin(), nodes.end(), deepest.node) != nodes.end()) {
      face = f;
      break;
    }
  }
  std::string body, hint;
  const auto length = [](double v) { return fmt::format("{:.4g} m", v); };
  if (shape == "sphere" || shape == "capsule") {
    body = shape == "sphere"
               ? fmt::format("its sphere (radius {}, centre {} m)", length(n.real("radius")),
                             vec(n.vec3("position")))
               : fmt::format("its capsule (radius {}, length {}, centre {} m)",
                             length(n.real("radius")), length(n.real("length")),
                             vec(n.vec3("position")));
    hint = "lengths are in metres unless a unit is written (radius: 10 mm)";
  } else if (shape == "plane") {
    body = fmt::format("its half-space (boundary through {} m, normal {} out of the body)",
                       vec(n.vec3("position")), vec(n.vec3("normal")));
    hint = "position is a point of the plane in metres unless a unit is written, and normal "
           "points out of the rigid body, towards the structure";
  } else {
    const fem::SurfaceTriangulation tri = contact.indenter().shape().triangulate();
    fem::Vec3 lo = fem::Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const fem::Vec3& v : tri.vertices) {
      lo = lo.cwiseMin(v);
      hi = hi.cwiseMax(v);
    }
    body = fmt::format("its STL surface (from {} to {} m with scale {:.4g})", vec(lo), vec(hi),
                       n.real("scale"));
    hint = "STL coordinates are taken in metres times 'scale' (scale: 0.001 for a file in mm), "
           "and 'position' translates them";
  }
  n.fail(fmt::format(
      "indenter '{}' starts inside the structure: node {} of face '{}' at {} m lies {:.4g} m "
      "deep inside {} (the face's elements are about {:.3g} m); a rigid indenter must start "
      "outside, touching at most. Check its size and position: {}",
      name, deepest.node, face, vec(model.mesh().node(deepest.node)), deepest.depth, body,
      element, hint));
}

}  // namespace

IndenterBuild build_indenter(const Node& n, const fem::Model& model,
                             const std::filesystem::path& case_dir, bool explicit_steps) {
  IndenterBuild b;
  b.name = n.string("name");
  const std::string shape = n.string("shape");
  const std::vector<std::string> face = n.strings("face");
  const auto faces = model.mesh().face_names();
  if (face.empty()) n["face"].fail("no face given; the mesh has: " + join_names(faces));
  for (std::size_t i = 0; i < face.size(); ++i) {
    if (std::find(faces.begin(), faces.end(), face[i]) == faces.end())
      n["face"].fail("unknown face '" + face[i] + "'; the mesh has: " + join_names(faces) +
                     did_you_mean(face[i], faces));
    if (std::find(face.begin(), face.begin() + static_cast<std::ptrdiff_t>(i), face[i]) !=
        face.begin() + static_cast<std::ptrdiff_t>(i))
      n["face"].fail("the face '" + face[i] + "' is named twice");
  }
  if (shape != "surface" && !n.has("position")) n.fail("shape " + shape + " needs 'position'");
  b.reference = n.has("position") ? n.vec3("position") : Eigen::Vector3d::Zero();
  std::shared_ptr<const fem::RigidShape> geometry;
  try {
    if (shape == "sphere") {
      require_keys(n, shape, {"radius"});
      forbid_keys(n, shape, {"length", "axis", "normal", "stl", "search_radius"});
      geometry = std::make_shared<fem::SphereShape>(b.reference, n.real("radius"));
    } else if (shape == "capsule") {
      require_keys(n, shape, {"radius", "length", "axis"});
      forbid_keys(n, shape, {"normal", "stl", "search_radius"});
      if (!(n.vec3("axis").norm() > 0.0)) n["axis"].fail("the capsule's axis must not be zero");
      geometry = std::make_shared<fem::CapsuleShape>(b.reference, n.vec3("axis"), n.real("length"),
                                                     n.real("radius"));
    } else if (shape == "plane") {
      require_keys(n, shape, {"normal"});
      forbid_keys(n, shape, {"radius", "length", "axis", "stl", "search_radius"});
      if (!(n.vec3("normal").norm() > 0.0)) n["normal"].fail("the plane's normal must not be zero");
      geometry = std::make_shared<fem::PlaneShape>(b.reference, n.vec3("normal"));
    } else {
      require_keys(n, shape, {"stl"});
      forbid_keys(n, shape, {"radius", "length", "axis", "normal"});
      std::filesystem::path file = n.string("stl");
      if (file.is_relative()) file = case_dir / file;
      Mesh stl;
      try {
        stl = read_stl(file, b.name, n.real("scale"));
      } catch (const Error& e) {
        n["stl"].fail(e.what());
      }
      std::vector<fem::Vec3> vertices;
      for (Eigen::Index i = 0; i < stl.size(); ++i)
        vertices.push_back(stl.points().row(i).transpose() + b.reference);
      std::vector<std::array<int, 3>> triangles;
      for (Eigen::Index t = 0; t < stl.num_triangles(); ++t)
        triangles.push_back({static_cast<int>(stl.triangles()(t, 0)),
                             static_cast<int>(stl.triangles()(t, 1)),
                             static_cast<int>(stl.triangles()(t, 2))});
      const double search = n.has("search_radius") ? n.real("search_radius")
                                                   : mean_face_size(model.mesh(), face);
      try {
        geometry = std::make_shared<fem::TriangulatedShape>(std::move(vertices), std::move(triangles), search);
      } catch (const fem::Error& e) {
        n["stl"].fail(e.what());
      }
    }
  } catch (const fem::Error& e) {
    n.fail(e.what());
  }

  const Node m = n["motion"];
  std::optional<fem::RigidIndenter> indenter;
  if (m.has("mass")) {
    if (m.has("table")) m["table"].fail("a free indenter (mass) moves under its forces: give its initial 'velocity', not a table");
    if (!explicit_steps)
      m["mass"].fail("a free indenter (motion.mass) moves explicitly with the structure: it needs "
                     "analysis.integrator: central-difference (transient); drive it with "
                     "motion.velocity or motion.table in static or Newmark analyses");
    const fem::Vec3 v0 = m.has("velocity") ? fem::Vec3(m.vec3("velocity")) : fem::Vec3::Zero();
    indenter.emplace(geometry, m.real("mass"), v0, m.vec3("gravity"));
  } else {
    if (m.has("table") == m.has("velocity"))
      m.fail("give the motion as 'velocity: [vx, vy, vz]' or 'table: [[t, vx, vy, vz], ...]' "
             "(driven), or 'mass' (free, with an initial velocity)");
    if (m.vec3("gravity").norm() > 0.0)
      m["gravity"].fail("gravity moves a free indenter only (motion.mass); a driven one follows "
                        "its velocity");
    indenter.emplace(geometry, m.has("table") ? velocity_table(m["table"])
                                              : fem::VelocityTable({{0.0, m.vec3("velocity")}}));
  }
  fem::IndenterContactOptions options;
  options.penalty_factor = n["penalty"].real("factor");
  options.tangential_factor = n["penalty"].real("tangential_factor");
  options.friction = n.real("friction");
  try {
    b.contact = std::make_unique<fem::IndenterContact>(b.name, model, face, std::move(*indenter), options);
  } catch (const fem::Error& e) {
    n.fail(e.what());
  }
  refuse_start_inside(n, b.name, shape, face, model, *b.contact);
  const fem::SurfaceTriangulation tri = b.contact->indenter().shape().triangulate();
  if (!tri.triangles.empty()) {
    Mesh::Points p(static_cast<Eigen::Index>(tri.vertices.size()), 3);
    for (std::size_t i = 0; i < tri.vertices.size(); ++i) p.row(static_cast<Eigen::Index>(i)) = tri.vertices[i].transpose();
    Mesh::Triangles t(static_cast<Eigen::Index>(tri.triangles.size()), 3);
    for (std::size_t i = 0; i < tri.triangles.size(); ++i)
      t.row(static_cast<Eigen::Index>(i)) << tri.triangles[i][0], tri.triangles[i][1], tri.triangles[i][2];
    b.has_surface = true;
    b.surface.mesh = Mesh(b.name, p, t);
    b.surface.writes.push_back(DataSpec{"displacement", 3, "m", DataKind::intensive});
    // a free body also takes forces on its surface (their resultant moves it: granules it has
    // broken in among); a driven one follows its table whatever pushes it
    if (b.contact->indenter().is_free())
      b.surface.reads.push_back(DataSpec{"force", 3, "N", DataKind::extensive});
    else
      b.surface.prescribed = true;  // the work it does on a reader is that reader's input
  }
  return b;
}

void write_indenter_vtp(const std::filesystem::path& file, const InterfaceMesh& surface,
                        const fem::IndenterContact& contact, const vtk::Options& options) {
  const Eigen::RowVector3d d = contact.indenter().displacement().transpose();
  const Mesh::Points moved = surface.mesh.points().rowwise() + d;
  write_vtp(file, surface.mesh, {{"displacement", d.replicate(surface.mesh.size(), 1)}}, {}, &moved,
            options);
}

}  // namespace partita::adapters
