// Building a FEM adapter from its validated case section: the mesh (a box, a panel or a Gmsh
// file), the model with its material (fem_material.cpp), constraints and loads, the analysis and
// its solver options, the coupling interfaces and their meshes, line probes, point monitors and
// rigid indenters; a static analysis is solved here.

#include <fmt/format.h>
#include <algorithm>

#include "fem_adapter.hpp"
#include "fem_material.hpp"
#include "fem_panel_config.hpp"
#include "fem_rupture.hpp"
#include "indenter_config.hpp"
#include "partita/fem/blas_runtime.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/face_area.hpp"
#include "partita/fem/self_contact.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"
#include "partita/interface/time_table.hpp"

namespace partita::adapters {

namespace {

using config::Node;

int component_index(const Node& n) {
  const std::string c = n.as_string();
  for (int i = 0; i < 3; ++i)
    if (FemAdapter::kComponents[static_cast<std::size_t>(i)] == c) return i;
  n.fail("unknown component '" + c + "'; allowed: x, y, z");
}

fem::TimeFunction ramp_function(double ramp) {
  if (ramp <= 0) return {};
  return [ramp](double t) { return std::min(1.0, std::max(0.0, t / ramp)); };
}

void require_name(const Node& n, const std::string& name, const std::vector<std::string>& known,
                  const char* what) {
  if (std::find(known.begin(), known.end(), name) == known.end())
    n.fail(std::string("unknown ") + what + " '" + name + "'; the mesh has: " + join_names(known) +
           did_you_mean(name, known));
}

// The largest generated box mesh accepted (a typing error beyond it would exhaust the memory).
constexpr double kMaxBoxCells = 2.0e7;
fem::Mesh build_mesh(const Node& m, const std::filesystem::path& case_dir) {
  const std::string e = m.string("element");
  const fem::ElementType element = e == "hex8"    ? fem::ElementType::Hex8
                                   : e == "hex20" ? fem::ElementType::Hex20
                                   : e == "tet4"  ? fem::ElementType::Tet4
                                                  : fem::ElementType::Tet10;
  if (m.has("panel")) return build_panel_mesh(m["panel"], element, kMaxBoxCells);
  if (m.has("box")) {
    fem::BoxSpec b;
    b.origin = m["box"].vec3("origin");
    b.size = m["box"].vec3("size");
    const auto cells = m["box"].integers("cells");
    // Counts are checked as reals first: a product of three longs can wrap.
    const double total = static_cast<double>(cells[0]) * static_cast<double>(cells[1]) *
                         static_cast<double>(cells[2]);
    if (total > kMaxBoxCells)
      m["box"]["cells"].fail(fmt::format(
          "{} x {} x {} = {:.3g} cells is more than {:.0e}, far beyond what one machine can solve "
          "(about 3 x 10^5 degrees of freedom take a minute to factorise); check the counts",
          cells[0], cells[1], cells[2], total, kMaxBoxCells));
    b.cells = {static_cast<int>(cells[0]), static_cast<int>(cells[1]), static_cast<int>(cells[2])};
    if (m["box"].has("wall_thickness")) {
      b.wall_thickness = m["box"].real("wall_thickness");
      b.wall_cells = static_cast<int>(m["box"].integer("wall_cells"));
      const double half = 0.5 * b.size.minCoeff();
      if (!(b.wall_thickness < half))
        m["box"]["wall_thickness"].fail(fmt::format(
            "a wall thickness of {:.4g} m leaves no cavity in a box whose smallest edge is {:.4g} "
            "m; allowed: 0 < wall_thickness < {:.4g} m (half the smallest edge)",
            b.wall_thickness, b.size.minCoeff(), half));
      const double walls = static_cast<double>(b.wall_cells) * 2.0;
      const double hollow_total = (static_cast<double>(cells[0]) + walls) *
                                  (static_cast<double>(cells[1]) + walls) *
                                  (static_cast<double>(cells[2]) + walls);
      if (hollow_total > kMaxBoxCells)
        m["box"]["wall_cells"].fail(fmt::format(
            "{} cells through the wall make {:.3g} cells in all, more than {:.0e}; check the "
            "counts",
            b.wall_cells, hollow_total, kMaxBoxCells));
    } else if (m["box"].has("wall_cells")) {
      m["box"]["wall_cells"].fail("wall_cells applies to a hollow box only: add wall_thickness");
    }
    b.element = element;
    fem::Mesh box_mesh = fem::make_box_mesh(b);
    apply_box_regions(box_mesh, m["box"]);
    return box_mesh;
  }
  std::filesystem::path file = m.string("gmsh");
  if (file.is_relative()) file = case_dir / file;
  if (!std::filesystem::exists(file))
    m["gmsh"].fail("mesh file '" + file.string() + "' does not exist");
  fem::Mesh mesh = fem::read_gmsh(file.string());
  const double scale = m.real("scale");
  if (scale != 1.0)
    for (std::size_t i = 0; i < mesh.num_nodes(); ++i) mesh.set_node(i, mesh.node(i) * scale);
  return mesh;
}

}  // namespace

std::unique_ptr<Solver> FemAdapter::create(const SolverContext& context) {
  return std::make_unique<FemAdapter>(context);
}

FemAdapter::FemAdapter(const SolverContext& context) : name_(context.name) {
  const Node& c = context.config;
  try {
    fem::Mesh mesh = build_mesh(c["mesh"], context.case_dir);
    // faces between elements (eroding contact)
    for (const Node& i : c["mesh"]["interior_faces"].items()) {
      const std::string iname = i.string("name");
      std::vector<int> regions;  // empty: every region
      if (i.has("regions")) {
        const auto wanted = i.strings("regions");
        if (wanted.empty())
          i["regions"].fail("an empty list: name the regions whose shared faces it holds, or "
                            "leave the key out for every region");
        for (const auto& r : wanted) {
          require_name(i["regions"], r, mesh.region_names(), "region");
          regions.push_back(mesh.region(r));
        }
      }
      if (mesh.has_face(iname))
        i["name"].fail("the mesh has a face '" + iname + "' already; choose another name (faces: " +
                       join_names(mesh.face_names()) + ")");
      const std::size_t added = mesh.add_interior_faces(iname, regions);
      if (added == 0)
        (i.has("regions") ? i["regions"] : i)
            .fail("no two elements of these regions share a face: nothing for erosion to expose");
      log::get("adapters")->info("fem '{}': face '{}': {} face elements (each face between two "
                                 "elements, from either side), in contact once erosion exposes "
                                 "them",
                                 context.name, iname, added);
    }
    const Node mat = c["material"];
    fem::Model model = build_fem_model(std::move(mesh), mat);
    const std::string hex8 = c["mesh"].string("hex8");
    model.set_hex8_formulation(hex8 == "full"      ? fem::Hex8Formulation::Full
                               : hex8 == "f-bar"   ? fem::Hex8Formulation::FBar
                               : hex8 == "reduced" ? fem::Hex8Formulation::Reduced
                                                   : fem::Hex8Formulation::IncompatibleModes);
    if (hex8 == "f-bar" && model.is_linear())
      c["mesh"]["hex8"].fail(
          "hex8: f-bar is an element of the nonlinear path; with material model linear-elastic "
          "use hex8: incompatible-modes (the default, which does not lock), or choose a "
          "nonlinear material.model");
    // a warning wherever the element in use locks: plain Hex8 always in bending, F-bar Hex8 in
    // bending of thin elements (one through a plate's thickness)
    if (hex8 == "full" || hex8 == "f-bar") {
      std::size_t hexes = 0, thin = 0;
      for (const auto& e : model.mesh().elements()) {
        if (e.type != fem::ElementType::Hex8) continue;
        ++hexes;
        Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
        for (auto n : e.node_span()) {
          lo = lo.cwiseMin(model.mesh().node(n));
          hi = hi.cwiseMax(model.mesh().node(n));
        }
        const Eigen::Vector3d ext = hi - lo;
        if (2.0 * ext.minCoeff() < ext.maxCoeff()) ++thin;
      }
      if (hexes > 0 && (hex8 == "full" || thin > 0)) {
        log::get("adapters")
            ->warn(
                "fem '{}': mesh.hex8: {} locks in bending ({} of {} Hex8 elements are thin): "
                "deflections too small and limit loads too high (a cantilever with one "
                "element through the depth: tip deflection about 35 % low); the default "
                "incompatible-modes does not lock",
                context.name, hex8, thin, hexes);
      }
    }
    const auto sets = model.mesh().node_set_names();
    const auto faces = model.mesh().face_names();

    for (const Node& k : c["constraints"].items()) {
      const std::string set = k.string("set");
      require_name(k["set"], set, sets, "node set");
      if (k.has("fix")) {
        std::vector<int> comps;
        for (const Node& x : k["fix"].items()) comps.push_back(component_index(x));
        model.fix(set, comps);
      } else {
        if (!k.has("component")) k.fail("a prescribed displacement needs 'component: x|y|z'");
        const double value = k.real("displacement");
        const double ramp = k.real("ramp");
        if (k.has("table")) {
          if (k.has("ramp")) k["table"].fail("give a ramp or a table, not both");
          const TimeTable table = TimeTable::from_node(k["table"]);
          model.prescribe(set, component_index(k["component"]),
                          [value, table](double t) { return value * table(t); });
        } else {
          model.prescribe(set, component_index(k["component"]), [value, ramp](double t) {
            return ramp > 0 ? value * std::min(1.0, t / ramp) : value;
          });
        }
      }
    }
    for (const Node& l : c["loads"].items()) {
      fem::TimeFunction amp = ramp_function(l.real("ramp"));
      if (l.has("table")) {
        if (l.has("ramp")) l["table"].fail("give a ramp or a table, not both");
        amp = [table = TimeTable::from_node(l["table"])](double t) { return table(t); };
      }
      if (l.has("gravity")) {
        if (l.has("face")) l["face"].fail("gravity acts on the whole body; remove 'face'");
        model.add_gravity(l.vec3("gravity"), amp);
        continue;
      }
      if (!l.has("face"))
        l.fail("a pressure, traction or force load needs 'face: <name>'; faces: " +
               join_names(faces));
      const std::string face = l.string("face");
      require_name(l["face"], face, faces, "face");
      if (l.has("pressure")) {
        model.add_pressure(face, l.real("pressure"), amp);
      } else if (l.has("force")) {
        // F spread evenly: t = F / A over the face's reference area (a follower of nothing:
        // fixed in direction and size, as a traction load)
        const double area = fem::face_area(model.mesh(), face);
        model.add_traction(face, l.vec3("force") / area, amp);
      } else {
        model.add_traction(face, l.vec3("traction"), amp);
      }
    }

    const Node an = c["analysis"];
    transient_ = an.string("type") == "transient";
    fem::SolverOptions options;
    options.newmark_beta = an["newmark"].real("beta");
    options.newmark_gamma = an["newmark"].real("gamma");
    options.mass =
        an.string("mass") == "lumped" ? fem::MassType::Lumped : fem::MassType::Consistent;
    options.rayleigh_alpha = an["rayleigh"].real("alpha");
    options.rayleigh_beta = an["rayleigh"].real("beta");
    if (an.string("integrator") == "central-difference") {
      if (options.mass != fem::MassType::Lumped)
        an["integrator"].fail("central-difference needs 'mass: lumped'");
      options.integrator = fem::Integrator::CentralDifference;
    }
    check_failure_keys(mat, transient_ && options.integrator == fem::Integrator::CentralDifference);
    if (an.has("mass_scaling_time_step")) {
      if (!transient_ || options.integrator != fem::Integrator::CentralDifference)
        an["mass_scaling_time_step"].fail(
            "mass scaling raises the stable step of central-difference analyses (type: "
            "transient, integrator: central-difference, mass: lumped); Newmark and static "
            "analyses have no stable-step limit: remove mass_scaling_time_step");
      options.mass_scaling_time_step = an.real("mass_scaling_time_step");
    }
    stable_step_factor_ = an.real("stable_step_factor");
    const std::string linear_solver = an.string("linear_solver");
    if (linear_solver == "cholmod") {
      if (!fem::cholmod_available())
        an["linear_solver"].fail(
            "'cholmod' is not built into this partita (configure with libsuitesparse-dev "
            "installed and -DPARTITA_CHOLMOD=ON); allowed here: auto, eigen-ldlt");
      options.linear_solver = fem::LinearSolver::Cholmod;
    } else if (linear_solver == "eigen-ldlt") {
      options.linear_solver = fem::LinearSolver::EigenLdlt;
    }
    const std::string ordering = an.string("fill_ordering");
    if (ordering == "nesdis")
      options.fill_ordering = fem::FillOrdering::Nesdis;
    else if (ordering == "metis")
      options.fill_ordering = fem::FillOrdering::Metis;
    else if (ordering == "amd")
      options.fill_ordering = fem::FillOrdering::Amd;
    const std::string threading = an.string("solve_threading");
    if (threading == "threaded")
      options.solve_threading = fem::SolveThreading::Threaded;
    else if (threading == "serial")
      options.solve_threading = fem::SolveThreading::Serial;
    const std::string factor_threading = an.string("factor_threading");
    if (factor_threading == "threaded")
      options.factor_threading = fem::FactorThreading::Threaded;
    else if (factor_threading == "serial")
      options.factor_threading = fem::FactorThreading::Serial;
    const Node nl = an["nonlinear"];
    options.newton.max_iterations = static_cast<int>(nl.integer("max_iterations"));
    options.newton.force_tolerance = nl.real("force_tolerance");
    options.newton.round_off_factor = nl.real("round_off_factor");
    options.newton.energy_tolerance = nl.real("energy_tolerance");
    options.newton.load_steps = static_cast<int>(nl.integer("load_steps"));
    options.newton.max_cutbacks = static_cast<int>(nl.integer("max_cutbacks"));
    options.newton.max_line_search_steps = static_cast<int>(nl.integer("line_search_steps"));
    options.newton.energy_line_search = nl.string("line_search") == "energy";
    // rigid indenters are contributions of the FE operator. The linear path takes them on every
    // integrator (K u plus them); a linear model with indenters in a static or Newmark analysis
    // stays on the nonlinear path's element-by-element operator all the same, so that its results
    // keep their bits (the linear path would be faster there)
    if (!c["indenters"].items().empty() &&
        !(model.is_linear() && options.integrator == fem::Integrator::CentralDifference))
      options.nonlinear_path = true;
    solver_ = std::make_unique<fem::StructuralSolver>(std::move(model), options);
    if (fem::resolve(options.linear_solver) == fem::LinearSolver::Cholmod) {
      const fem::BlasInfo blas = fem::use_serial_blas();
      log::get("adapters")->debug("fem '{}': BLAS {} ({}, {}), {} thread(s) per call", name_,
                                  blas.name, blas.library.empty() ? "not loaded" : blas.library,
                                  blas.threading, blas.threads);
    }
    // Newton iterations, load steps and cut-backs of the nonlinear path, at debug level (a
    // line per Newton iteration: microseconds beside the factorisation of the tangent)
    solver_->set_progress_callback(
        [logger = log::get("adapters"), name = name_](std::string_view line) {
          logger->debug("fem '{}': {}", name, line);
        });
    {
      Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
      for (const auto& x : solver_->mesh().nodes()) {
        lo = lo.cwiseMin(x);
        hi = hi.cwiseMax(x);
      }
      model_size_ = (hi - lo).norm();
    }

    const auto ifaces = c["interfaces"].items();
    for (const Node& i : ifaces) {
      Interface itf;
      itf.name = i.string("name");
      itf.face = i.string("face");
      require_name(i["face"], itf.face, faces, "face");
      for (const auto& other : interfaces_)
        if (other.name == itf.name)
          i["name"].fail("interface name '" + itf.name + "' is used twice");
      const fem::FaceMesh fm = solver_->face_mesh(itf.face);
      itf.nodes = fm.nodes;
      Mesh::Triangles tris(static_cast<Eigen::Index>(fm.triangles.size()), 3);
      for (std::size_t t = 0; t < fm.triangles.size(); ++t)
        tris.row(static_cast<Eigen::Index>(t)) << fm.triangles[t][0], fm.triangles[t][1],
            fm.triangles[t][2];
      InterfaceMesh nodes;
      nodes.mesh = Mesh(itf.name, fm.positions, tris);
      nodes.writes.push_back(DataSpec{"displacement", 3, "m", DataKind::intensive});
      nodes.reads.push_back(DataSpec{"force", 3, "N", DataKind::extensive});
      const auto qps = solver_->face_quadrature_points(itf.face);
      Mesh::Points qx(static_cast<Eigen::Index>(qps.size()), 3);
      for (std::size_t q = 0; q < qps.size(); ++q) {
        qx.row(static_cast<Eigen::Index>(q)) = qps[q].position.transpose();
        itf.qp_weights.push_back(qps[q].weight);
      }
      // the triangles' centroids and the element under each (for "attached")
      Mesh::Points centroids(static_cast<Eigen::Index>(fm.triangles.size()), 3);
      for (std::size_t t = 0; t < fm.triangles.size(); ++t) {
        centroids.row(static_cast<Eigen::Index>(t)).setZero();
        for (int v : fm.triangles[t])
          centroids.row(static_cast<Eigen::Index>(t)) += fm.positions.row(v) / 3.0;
        itf.triangle_elements.push_back(
            fm.cell_elements[static_cast<std::size_t>(fm.triangle_cells[t])]);
        itf.triangle_across.push_back(
            fm.cell_across[static_cast<std::size_t>(fm.triangle_cells[t])]);
      }
      InterfaceMesh centres;
      centres.mesh = Mesh(itf.name + "_centres", centroids);
      centres.writes.push_back(DataSpec{"attached", 1, "", DataKind::intensive});
      InterfaceMesh quad;
      quad.mesh = Mesh(itf.name + "_quadrature", qx);
      quad.mesh.set_weights(Eigen::Map<const Eigen::VectorXd>(
          itf.qp_weights.data(), static_cast<Eigen::Index>(itf.qp_weights.size())));
      quad.reads.push_back(DataSpec{"traction", 3, "Pa", DataKind::intensive});
      itf.nodal_forces = Eigen::MatrixX3d::Zero(static_cast<Eigen::Index>(itf.nodes.size()), 3);
      itf.tractions = Eigen::MatrixX3d::Zero(qx.rows(), 3);
      meshes_.push_back(std::move(nodes));
      meshes_.push_back(std::move(quad));
      meshes_.push_back(std::move(centres));
      interfaces_.push_back(std::move(itf));
    }
    for (const Node& p : c["probes"].items()) {
      std::vector<LineProbe::Field> fields;
      for (const std::string& f :
           p.has("fields") ? p.strings("fields") : std::vector<std::string>{"displacement"})
        fields.push_back(f == "stress"      ? LineProbe::Field::stress
                         : f == "von_mises" ? LineProbe::Field::von_mises
                         : f == "equivalent_plastic_strain"
                             ? LineProbe::Field::equivalent_plastic_strain
                             : LineProbe::Field::displacement);
      const std::string pname = p.string("name");
      for (const auto& other : probes_)
        if (other.name() == pname) p["name"].fail("probe name '" + pname + "' is used twice");
      if (const fem::Vec3 d = p.vec3("to") - p.vec3("from");
          !(d.norm() > 1e-12 * std::max(1.0, p.vec3("from").norm())))
        p["to"].fail(fmt::format(
            "line probe '{}': 'to' equals 'from' ({}, {}, {}): a line probe samples a segment of "
            "positive length; give 'to' another point",
            pname, p.vec3("from").x(), p.vec3("from").y(), p.vec3("from").z()));
      try {
        probes_.emplace_back(pname, solver_->mesh(), p.vec3("from"), p.vec3("to"),
                             static_cast<int>(p.integer("points")), fields);
      } catch (const fem::Error& e) {
        p.fail(e.what());
      }
    }
    for (const Node& p : c["points"].items()) {
      const std::string pname = p.string("name");
      for (const auto& i : interfaces_)
        if (i.name == pname)
          p["name"].fail("'" + pname +
                         "' names an interface already; its monitor quantities would be the "
                         "same: give the point another name");
      for (const auto& other : points_)
        if (other.name == pname) p["name"].fail("point name '" + pname + "' is used twice");
      if (!locator_) locator_ = std::make_unique<MeshLocator>(solver_->mesh());
      const auto at = locator_->locate(p.vec3("at"));
      if (!at)
        p["at"].fail(fmt::format(
            "point '{}' at ({}, {}, {}) lies in no element of the model (give a point inside "
            "or on its surface, in the reference configuration)",
            pname, p.vec3("at").x(), p.vec3("at").y(), p.vec3("at").z()));
      points_.push_back({pname, *at});
    }
    // --- rigid indenters (indenter_config.cpp) ---
    for (const Node& n : c["indenters"].items()) {
      IndenterBuild b = build_indenter(
          n, solver_->model(), context.case_dir,
          transient_ && options.integrator == fem::Integrator::CentralDifference);
      for (const auto& other : indenters_)
        if (other.name == b.name) n["name"].fail("indenter name '" + b.name + "' is used twice");
      for (const auto& i : interfaces_)
        if (i.name == b.name)
          n["name"].fail("'" + b.name + "' names an interface already: give the indenter another name");
      indenters_.push_back({b.name, b.reference, b.contact.get(), b.has_surface});
      if (b.has_surface) meshes_.push_back(std::move(b.surface));
      // an eroded element's nodes leave the surface the indenter touches
      b.contact->set_detached(
          [s = solver_.get()](std::size_t node) { return s->node_detached(node); });
      b.contact->set_eroded(
          [s = solver_.get()](std::size_t element) { return s->element_eroded(element); });
      solver_->add_contribution(std::move(b.contact));
    }
    if (c.has("self_contact")) {
      const Node sc = c["self_contact"];
      if (!transient_ || options.integrator != fem::Integrator::CentralDifference)
        sc.fail("self contact offers no tangent: it works in central-difference analyses only "
                "(analysis: {type: transient, integrator: central-difference})");
      if (!(sc.real("depth") < 1.0))
        sc["depth"].fail(fmt::format("depth {} is a fraction of the element's thickness under a "
                                     "face: give 0 < depth < 1",
                                     sc.real("depth")));
      const auto contact_faces = sc.strings("faces");
      if (contact_faces.empty()) sc["faces"].fail("an empty list: name the faces that may touch each other");
      for (const auto& f : contact_faces) require_name(sc["faces"], f, solver_->mesh().face_names(), "face");
      fem::SelfContactOptions so;
      so.penalty_factor = sc.real("penalty_factor");
      so.depth = sc.real("depth");
      auto self = std::make_unique<fem::SelfContact>("self_contact", solver_->model(), contact_faces, so);
      self->set_detached([s = solver_.get()](std::size_t node) { return s->node_detached(node); });
      self->set_eroded([s = solver_.get()](std::size_t element) { return s->element_eroded(element); });
      log::get("adapters")
          ->info("fem '{}': self contact over {}: {} triangles exposed now, {} face nodes",
                 context.name, join_names(contact_faces), self->triangles_in_contact_surface(),
                 self->surface_nodes());
      self_contact_ = self.get();
      solver_->add_contribution(std::move(self));
    }
    if (!transient_) solver_->solve_static();
  } catch (const fem::Error& e) {
    c.fail(std::string("FEM model of participant '") + context.name +
           "': " + with_newton_keys(e.what()));
  }
  log::get("adapters")
      ->info("fem '{}': {} nodes, {} elements, {} dofs, {} analysis", name_,
             solver_->mesh().num_nodes(), solver_->mesh().num_elements(), solver_->num_dofs(),
             transient_ ? "transient" : "static");
  if (const double target = solver_->options().mass_scaling_time_step; target > 0.0) {
    double largest = 1.0;
    for (std::size_t e = 0; e < solver_->mesh().num_elements(); ++e)
      largest = std::max(largest, solver_->mass_scale_factor(e));
    const double mass = solver_->physical_mass(), added = solver_->added_mass();
    log::get("adapters")
        ->info(
            "fem '{}': mass scaling to a stable step of {:.4g} s: {} of {} elements scaled "
            "(largest factor {:.4g}), added mass {:.6g} kg = {:.4g} % of the model's {:.6g} kg; "
            "stable step now {:.4g} s",
            name_, target, solver_->mass_scaled_elements(), solver_->mesh().num_elements(),
            largest, added, mass > 0.0 ? 100.0 * added / mass : 0.0, mass,
            solver_->stable_time_step());
  }
}

}  // namespace partita::adapters
