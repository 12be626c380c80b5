#include "fem_adapter.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <limits>
#include <sstream>

#include "partita/fem/blas_runtime.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/face_area.hpp"
#include "partita/fem/state_io.hpp"

#include "fem_output.hpp"
#include "fem_material.hpp"
#include "fem_panel_config.hpp"
#include "fem_rupture.hpp"
#include "indenter_config.hpp"
#include "line_probe.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"
#include "partita/interface/output.hpp"
#include "partita/interface/time_table.hpp"

namespace partita::adapters {

namespace {

using config::Node;
using config::Spec;

const std::vector<std::string> kComponents = {"x", "y", "z"};

std::shared_ptr<Spec> make_spec() {
  auto box =
      std::make_shared<Spec>("box",
                             "a structured box mesh with faces and node sets xmin, xmax, ymin, "
                             "ymax, zmin, zmax and all; with wall_thickness a closed hollow "
                             "box (also inner)");
  box->reals("origin", "lower corner").unit("m").size(3).required();
  box->reals("size", "edge lengths").unit("m").size(3).min(0.0, true).required();
  box->integers("cells", "cells along x, y, z (hollow box: across the cavity)")
      .size(3)
      .min(1)
      .required();
  box->real("wall_thickness",
            "a closed hollow box: walls of this thickness around an empty cavity (> 0 and < half "
            "the smallest edge); adds the face and node set 'inner' (the cavity's whole surface, "
            "normals into the cavity) and faces inner_xmin ... inner_zmax")
      .unit("m")
      .positive();
  box->integer("wall_cells", "hollow box: cells through the wall thickness").min(1).def(1);
  box->list("regions",
            "element regions (parts: energies by part, the failed element's part); elements "
            "whose centre lies in no listed box stay in region 'all'; a later box takes over",
            fem_box_region_spec());

  auto mesh = std::make_shared<Spec>(
      "mesh", "the finite element mesh: a box, a cellular panel or a Gmsh 4.1 ASCII file");
  mesh->section("box", "structured box", box);
  mesh->section("panel", "structured cellular panel (double-hull section)", fem_panel_spec());
  mesh->string(
      "gmsh",
      "Gmsh 4.1 ASCII .msh file (physical groups become named faces and node sets), relative "
      "to the case file");
  mesh->real("scale", "factor applied to the Gmsh coordinates (e.g. 1.0e-3 for a file in mm)")
      .positive()
      .def(1.0);
  mesh->choice("element", "element type of the box or panel mesh (Gmsh files carry their own)",
               {"hex8", "hex20", "tet4", "tet10"})
      .def("hex8");
  mesh->choice("hex8",
               "Hex8 formulation: incompatible-modes (Wilson/Taylor's QM6 on the linear path; on "
               "the nonlinear path the same modes as enhanced assumed strains, the EAS Hex8 of "
               "Simo & Armero 1992 / Simo, Armero & Taylor 1993, with 6 integration points "
               "through thin elements: no shear or volumetric locking, one element through a "
               "plate's thickness bends and yields right), full (plain 2x2x2: locks in bending "
               "and for nu -> 0.5 or plastic flow) or f-bar (nonlinear path only: F_bar = "
               "(J_bar/J)^(1/3) F, no volumetric locking, still stiff in bending of thin plates) "
               "or reduced (central-difference analyses only, the fast explicit plate element: one "
               "point in the plane and 6 through a plate-like element's thickness, 2 through others; "
               "hourglass stabilisation after Flanagan & Belytschko 1981 with Belytschko & "
               "Bindeman 1993's assumed-strain stiffnesses; one enhanced thickness strain against "
               "Poisson thickness locking; about 25 times faster per element than the EAS Hex8 "
               "with j2-plasticity)",
               {"incompatible-modes", "full", "f-bar", "reduced"})
      .def("incompatible-modes");
  mesh->one_of({"box", "panel", "gmsh"});

  auto constraint = std::make_shared<Spec>("constraint", "a Dirichlet condition on a node set");
  constraint
      ->string("set",
               "node set (box: all, xmin ... zmax; panel: all, outer, inner, xmin ... ymax, "
               "cell_<i>_<j>; Gmsh: physical group names)")
      .required();
  constraint->strings("fix", "components held at zero").choices(kComponents);
  constraint->choice("component", "component of a prescribed displacement", kComponents);
  constraint->real("displacement", "prescribed displacement of that component (reached over ramp)")
      .unit("m");
  constraint->real("ramp", "time over which the prescribed displacement grows linearly from 0")
      .unit("s")
      .non_negative()
      .def(0.0);
  constraint->any("table",
                  std::string("instead of ramp: the displacement times ") + TimeTable::doc());
  constraint->one_of({"fix", "displacement"});

  auto load = std::make_shared<Spec>(
      "load", "a load: pressure, traction or total force on a face, or gravity");
  load->string(
      "face",
      "face name (box: xmin ... zmax; panel: outer, inner, xmin ... ymax, cell_<i>_<j>; Gmsh: "
      "physical surface names)");
  load->real("pressure",
             "uniform pressure, positive pushing into the body (against the outward normal)")
      .unit("Pa");
  load->reals("traction", "uniform traction vector").unit("Pa").size(3);
  load->reals("force",
              "total force on the face, spread as the uniform traction force / area (the face's "
              "reference area)")
      .unit("N")
      .size(3);
  load->reals("gravity", "gravitational acceleration acting on the whole body")
      .unit("m/s^2")
      .size(3);
  load->real("ramp",
             "time over which the load grows linearly from 0 to its value (0: applied at once)")
      .unit("s")
      .non_negative()
      .def(0.0);
  load->any("table", std::string("instead of ramp: the load times ") + TimeTable::doc());
  load->one_of({"pressure", "traction", "force", "gravity"});

  auto probe = std::make_shared<Spec>(
      "probe", "a line probe: N points from 'from' to 'to', sampled at every output time");
  probe->string("name", "file names DIR/probes/<participant>_<name>_<frame>.csv").required();
  probe->reals("from", "start of the segment").unit("m").size(3).required();
  probe->reals("to", "end of the segment").unit("m").size(3).required();
  probe->integer("points", "points along the segment").min(2).def(50);
  probe->strings("fields", "what to sample (default: displacement)")
      .choices({"displacement", "stress", "von_mises", "equivalent_plastic_strain"});

  auto point = std::make_shared<Spec>(
      "point", "a point monitor: the displacement interpolated at a point of the model");
  point->string("name",
                "monitor quantities <name>.displacement_x, _y, _z (and, with a nonlinear "
                "material, <name>.equivalent_plastic_strain: the mean of the element's points)")
      .required();
  point->reals("at", "the point, in the reference configuration (inside or on the model)")
      .unit("m")
      .size(3)
      .required();

  auto interface = std::make_shared<Spec>("interface", "a coupling interface on a face");
  interface->string("name", "interface name: meshes <name> (nodes), <name>_quadrature (quadrature points) and <name>_centres (writes 'attached' per triangle of <name>: 0 once its element is eroded)")
      .required();
  interface->string("face", "the face it lies on").required();

  auto newmark = std::make_shared<Spec>("newmark", "Newmark parameters");
  newmark->real("beta", "beta (1/4: average acceleration)").positive().max(0.5).def(0.25);
  newmark->real("gamma", "gamma (1/2: no numerical damping)").min(0.5).max(1.0).def(0.5);
  auto rayleigh = std::make_shared<Spec>(
      "rayleigh",
      "Rayleigh damping C = alpha M + beta K0, K0 the stiffness at rest (nonlinear materials: "
      "the tangent at u = 0); beta lowers the central-difference stable step to (2/omega_max)"
      "(sqrt(1 + xi^2) - xi), xi = beta omega_max / 2");
  rayleigh->real("alpha", "mass-proportional coefficient").unit("1/s").non_negative().def(0.0);
  rayleigh->real("beta", "stiffness-proportional coefficient").unit("s").non_negative().def(0.0);
  auto analysis = std::make_shared<Spec>("analysis", "static or transient analysis");
  analysis
      ->choice("type", "transient (Newmark) or static (each step solves K u = F(t))",
               {"transient", "static"})
      .def("transient");
  analysis->section("newmark", "Newmark parameters", newmark);
  analysis->choice("mass", "mass matrix", {"consistent", "lumped"}).def("consistent");
  analysis->section("rayleigh", "Rayleigh damping", rayleigh);
  analysis
      ->choice("integrator",
               "transient time integration: newmark (implicit) or central-difference (explicit, "
               "needs mass: lumped; the coupling's auto substeps use its stable step)",
               {"newmark", "central-difference"})
      .def("newmark");
  analysis
      ->real("stable_step_factor",
             "central-difference: the step offered to the coupling is this times the element "
             "estimate (the element eigenvalue bound)")
      .range(0.0, 1.0)
      .def(0.9);
  analysis
      ->real("mass_scaling_time_step",
             "central-difference: mass scaling for quasi-static runs (LS-DYNA's DT2MS, Abaqus' "
             "fixed mass scaling): each element whose stable step is below this target gets its "
             "density scaled by (target / dt_e)^2, so that no element limits the step below it "
             "(the step offered is then stable_step_factor times the target, or less where a "
             "contact's penalty limits it); the log and the monitors added_mass and "
             "added_mass_percent say what was added (kinetic energy and the energy balance use "
             "the scaled mass, gravity the physical one). Keep the added mass small where the "
             "inertia matters: it slows the structure's waves and lowers its frequencies")
      .unit("s")
      .positive();
  analysis
      ->choice("linear_solver",
               "sparse direct solver of static solves, Newmark's K_eff and Newton's tangents: "
               "cholmod (SuiteSparse's supernodal Cholesky, NESDIS nested-dissection ordering; "
               "only in a build with CHOLMOD), eigen-ldlt (Eigen's simplicial LDL^T, AMD "
               "ordering), or auto (cholmod when built in, else eigen-ldlt); both agree to "
               "round-off",
               {"auto", "cholmod", "eigen-ldlt"})
      .def("auto");
  analysis
      ->choice("fill_ordering",
               "CHOLMOD's fill-reducing ordering: nesdis (CHOLMOD's nested dissection: METIS "
               "separators, then constrained minimum degree), metis (METIS_NodeND), amd "
               "(approximate minimum degree: the quickest analysis, more fill on large thin "
               "plates), or auto (nesdis); no effect with eigen-ldlt (AMD)",
               {"auto", "nesdis", "metis", "amd"})
      .def("auto");
  analysis
      ->choice("solve_threading",
               "the two triangular solves with a CHOLMOD factor (a linear static or Newmark "
               "step): threaded (the factor's elimination tree shared among the --threads), "
               "serial (CHOLMOD's own solve, one thread), or auto (threaded for factors of at "
               "least 2e6 entries); results never depend on the thread count, threaded and "
               "serial differ by round-off",
               {"auto", "threaded", "serial"})
      .def("auto");
  analysis
      ->choice("factor_threading",
               "the numeric factorisation of a CHOLMOD factor (a linear static solve, Newmark's "
               "K_eff, Newton's tangents): threaded (partita's supernodal factorisation, subtrees "
               "of the elimination "
               "tree and the rows of large supernodes shared among the --threads), serial "
               "(CHOLMOD's own, one thread), or auto (threaded for factors of at least 2e6 "
               "entries); results never depend on the thread count, threaded and serial differ "
               "by round-off",
               {"auto", "threaded", "serial"})
      .def("auto");
  auto nonlinear = std::make_shared<Spec>(
      "nonlinear", "Newton iterations of neo-hooke and j2-plasticity (static and Newmark)");
  nonlinear->integer("max_iterations", "Newton iterations per load or time step").min(1).def(25);
  nonlinear
      ->real("force_tolerance",
             "converged when |R| <= this * F_ref, F_ref the largest norm of the forces in the "
             "balance at the iterate (internal forces with the reactions, loads, inertia: as "
             "Abaqus, independent of the load's size and of the number of load steps), or when "
             "|R| is at round-off (round_off_factor)")
      .positive()
      .def(1e-8);
  nonlinear
      ->real("round_off_factor",
             "converged whatever force_tolerance says when |R| <= this * r_eps, r_eps a bound of "
             "the round-off of the assembled internal force (eps (|P| + 3 A_max |F|) |grad N| dV "
             "summed over the elements): the floor double precision allows (a steel cantilever's "
             "|R| stalls at 0.004-0.02 r_eps, near 1e-7 N, whatever the load)")
      .positive()
      .def(0.1);
  nonlinear
      ->real("energy_tolerance", "and |du . R| <= this * (first iteration's), or |R| at round-off")
      .positive()
      .def(1e-14);
  nonlinear->integer("load_steps", "static: increments from the current state to the target")
      .min(1)
      .def(1);
  nonlinear->integer("max_cutbacks", "halvings of a failed load or time step before giving up")
      .min(0)
      .def(8);
  nonlinear->integer("line_search_steps", "backtracking halvings of a Newton step").min(0).def(6);
  nonlinear
      ->choice("line_search",
               "what a line-search step must lower: energy (|R| or the energy slope |du . R| to "
               "0.8 of the step's start: bending structures that rotate and nearly "
               "incompressible ones, whose full Newton steps raise |R| while they lower the "
               "energy) or residual (|R| only)",
               {"residual", "energy"})
      .def("energy");
  analysis->section("nonlinear", "Newton solver of the nonlinear materials", nonlinear);

  auto s =
      std::make_shared<Spec>("fem",
                             "native FEM (solvers/fem): Hex8 (incompatible modes; EAS when "
                             "nonlinear), Hex20, Tet4, "
                             "Tet10; linear elastic, Neo-Hooke or J2 plasticity; static, Newmark "
                             "or central-difference transient");
  s->section("mesh", "the mesh", mesh).required();
  s->section("material", "the material", fem_material_spec()).required();
  s->list("constraints", "Dirichlet conditions", constraint);
  s->list("loads", "applied loads", load);
  s->list("probes",
          "line probes: one CSV per output time along a segment (s, x, y, z, the fields; the "
          "stress is the element-averaged nodal stress interpolated)",
          probe);
  s->list("points",
          "point monitors: <name>.displacement_x/_y/_z, the displacement at a point of the "
          "reference configuration (interpolated in the element that holds it)",
          point);
  s->list("interfaces",
          "coupling interfaces (faces whose meshes the coupling can use, and whose mean "
          "displacement and received force are monitor quantities)",
          interface);
  s->section("analysis", "analysis type and time integration", analysis);
  s->list("indenters",
          "rigid indenters in penalty contact with an FE face (part of this model's operator; a "
          "linear-elastic model keeps its fast K u in central difference, and takes the "
          "nonlinear path, element by element, in static and Newmark analyses)",
          indenter_spec());
  return s;
}

int component_index(const Node& n) {
  const std::string c = n.as_string();
  for (int i = 0; i < 3; ++i)
    if (kComponents[static_cast<std::size_t>(i)] == c) return i;
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

// A solver error with the case file's keys named where the solver names a Newton option
// (the library speaks of NewtonOptions' members, which are the keys under analysis.nonlinear).
std::string with_newton_keys(const std::string& what) {
  if (what.find("round_off_factor") == std::string::npos) return what;
  return what +
         " (keys analysis.nonlinear.force_tolerance and analysis.nonlinear.round_off_factor)";
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

std::shared_ptr<const config::Spec> FemAdapter::spec() {
  static const std::shared_ptr<const config::Spec> s = make_spec();
  return s;
}

std::unique_ptr<Solver> FemAdapter::create(const SolverContext& context) {
  return std::make_unique<FemAdapter>(context);
}

FemAdapter::FemAdapter(const SolverContext& context) : name_(context.name) {
  const Node& c = context.config;
  try {
    fem::Mesh mesh = build_mesh(c["mesh"], context.case_dir);
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
    // rigid indenters are contributions of the FE operator: the nonlinear path's, or on the
    // linear path K u plus them (central difference only)
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

std::size_t FemAdapter::find_interface(std::string_view mesh, Part* part) const {
  for (std::size_t k = 0; k < interfaces_.size(); ++k) {
    const auto& i = interfaces_[k];
    if (mesh == i.name || mesh == i.name + "_quadrature" || mesh == i.name + "_centres") {
      *part = mesh == i.name                ? Part::nodes
              : mesh == i.name + "_centres" ? Part::centres
                                            : Part::quadrature;
      return k;
    }
  }
  throw Error("fem '" + name_ + "' has no mesh '" + std::string(mesh) + "'");
}

// The interfaces' nodal forces go to the solver as one set (StructuralSolver::set_nodal_forces
// re-sums every coupling load over the whole force vector). read() only stores an interface's
// forces and marks them pending: with N interfaces and a read per interface per substep, applying
// at every read cost N^2 sums a substep (9 interfaces: 63 a window of 7 substeps, 7 % of the coarse
// double hull's run). They are applied once, before the step (and before anything that stores the
// solver's loads); the sum and its order are the same, so the results are bit for bit unchanged.
void FemAdapter::apply_nodal_forces() {
  if (!forces_pending_) return;
  forces_pending_ = false;
  std::size_t n = 0;
  for (const auto& i : interfaces_)
    if (i.has_forces) n += i.nodes.size();
  force_nodes_.clear();  // (work arrays: no allocation once they have grown)
  force_rows_.resize(static_cast<Eigen::Index>(n), 3);
  Eigen::Index row = 0;
  for (const auto& i : interfaces_) {
    if (!i.has_forces) continue;
    force_nodes_.insert(force_nodes_.end(), i.nodes.begin(), i.nodes.end());
    force_rows_.middleRows(row, i.nodal_forces.rows()) = i.nodal_forces;
    row += i.nodal_forces.rows();
  }
  solver_->set_nodal_forces(force_nodes_, force_rows_);
}

void FemAdapter::read(std::string_view mesh, std::string_view data, const Eigen::MatrixXd& values) {
  for (const auto& ind : indenters_) {
    if (!ind.has_surface || ind.name != mesh) continue;
    if (data != "force" || !ind.contact->indenter().is_free())
      throw Error("fem '" + name_ + "' reads only 'force' on indenter mesh '" + ind.name +
                  "', and only when the indenter is free (motion.mass)");
    // the resultant of the forces on the surface's vertices moves the rigid body
    ind.contact->set_external_force(values.colwise().sum().transpose());
    return;
  }
  Part part = Part::nodes;
  Interface& i = interfaces_[find_interface(mesh, &part)];
  if (part == Part::quadrature && data == "traction") {
    i.tractions = values;
    i.has_tractions = true;
    solver_->set_face_tractions_at_quadrature_points(i.face, i.tractions);
  } else if (part == Part::nodes && data == "force") {
    if (values.rows() != static_cast<Eigen::Index>(i.nodes.size()) || values.cols() != 3)
      throw Error("fem '" + name_ + "': 'force' on mesh '" + i.name + "' needs " +
                  std::to_string(i.nodes.size()) + " rows of 3, got " +
                  std::to_string(values.rows()) + " x " + std::to_string(values.cols()));
    if (!values.allFinite())
      throw Error("fem '" + name_ + "': non-finite 'force' on mesh '" + i.name + "'");
    i.nodal_forces = values;
    i.has_forces = true;
    forces_pending_ = true;  // applied before the step (apply_nodal_forces)
  } else {
    throw Error("fem '" + name_ + "' reads 'force' on mesh '" + i.name + "' and 'traction' on '" +
                i.name + "_quadrature', not '" + std::string(data) + "' on '" + std::string(mesh) +
                "'");
  }
}

void FemAdapter::write(std::string_view mesh, std::string_view data, Eigen::MatrixXd& values) {
  for (const auto& ind : indenters_) {
    if (!ind.has_surface || ind.name != mesh) continue;
    if (data != "displacement")
      throw Error("fem '" + name_ + "' writes only 'displacement' on indenter mesh '" + ind.name + "'");
    // a translation: every vertex moves with the indenter
    for (const auto& m : meshes_)
      if (m.mesh.name() == ind.name)
        values = ind.contact->indenter().displacement().transpose().replicate(m.mesh.size(), 1);
    return;
  }
  Part part = Part::nodes;
  const Interface& i = interfaces_[find_interface(mesh, &part)];
  if (part == Part::centres && data == "attached") {
    // 1 while the element under the triangle is in the structure, 0 once eroded
    values.resize(static_cast<Eigen::Index>(i.triangle_elements.size()), 1);
    for (std::size_t t = 0; t < i.triangle_elements.size(); ++t)
      values(static_cast<Eigen::Index>(t), 0) =
          solver_->element_eroded(i.triangle_elements[t]) ? 0.0 : 1.0;
    return;
  }
  if (part != Part::nodes || data != "displacement")
    throw Error("fem '" + name_ + "' writes 'displacement' on mesh '" + i.name +
                "' and 'attached' on '" + i.name + "_centres', not '" + std::string(data) +
                "' on '" + std::string(mesh) + "'");
  values = solver_->displacements(i.nodes);
}

void FemAdapter::advance(double dt) {
  apply_nodal_forces();
  u_before_ = solver_->displacement();  // (no allocation after the first step: same size)
  try {
    if (transient_)
      solver_->step(dt);
    else
      solver_->step_static(dt);  // quasi-static: equilibrium with the loads at the new time
  } catch (const fem::Error& e) {
    throw Error("fem '" + name_ + "' at t = " + fmt::format("{:.6g}", solver_->time()) +
                " s: " + with_newton_keys(e.what()));
  }
  failure_log_.after_step(*solver_, name_);
  // the work of each interface's loads over this step: 1/2 (f_k + f_k+1) . du
  du_ = solver_->displacement() - u_before_;
  for (auto& i : interfaces_)
    i.audit.load_step(
        du_, i.has_tractions ? &i.tractions : nullptr,
        [&](const Eigen::MatrixX3d& t) { return solver_->face_traction_work(i.face, t, du_); },
        i.nodes, i.has_forces ? &i.nodal_forces : nullptr);
}

std::optional<double> FemAdapter::interface_work(std::string_view mesh) const {
  for (const auto& ind : indenters_)  // a free indenter: the work of the forces it read on it
    if (ind.has_surface && ind.name == mesh)
      return ind.contact->indenter().is_free() ? std::optional<double>(ind.contact->indenter().external_work())
                                               : std::nullopt;
  Part part = Part::nodes;
  return interfaces_[find_interface(mesh, &part)].audit.work();
}

double FemAdapter::stable_time_step() const {
  if (!transient_ || solver_->options().integrator != fem::Integrator::CentralDifference)
    return std::numeric_limits<double>::infinity();
  return stable_step_factor_ * solver_->stable_time_step();
}

void FemAdapter::save_checkpoint() {
  apply_nodal_forces();  // the state holds the loads read so far
  checkpoint_ = solver_->save_state();
  for (auto& i : interfaces_) {
    i.audit.save_checkpoint();
    i.nodal_forces_checkpoint = i.nodal_forces;
    i.tractions_checkpoint = i.tractions;
    i.has_forces_checkpoint = i.has_forces;
    i.has_tractions_checkpoint = i.has_tractions;
  }
  has_checkpoint_ = true;
}

void FemAdapter::restore_checkpoint() {
  if (!has_checkpoint_)
    throw Error("fem '" + name_ + "': restore_checkpoint() before save_checkpoint()");
  solver_->restore_state(checkpoint_);
  forces_pending_ = false;  // the checkpoint's loads hold until the next read
  failure_log_.restored(*solver_);
  for (auto& i : interfaces_) {  // and the values read then: the loads the restored solver holds
    i.audit.restore_checkpoint();
    i.nodal_forces = i.nodal_forces_checkpoint;
    i.tractions = i.tractions_checkpoint;
    i.has_forces = i.has_forces_checkpoint;
    i.has_tractions = i.has_tractions_checkpoint;
  }
}

std::string FemAdapter::check_state() const {
  const Eigen::VectorXd& u = solver_->displacement();
  if (!u.allFinite())
    return "the displacement has non-finite values: the structural step failed; check the "
           "loads, constraints (a free rigid-body motion) and the coupled forces";
  const double d = solver_->max_displacement();
  if (d > model_size_)
    return fmt::format(
        "a node moved {:.3g} m, more than the model's size ({:.3g} m, the diagonal of its "
        "bounding box): the run is diverging or the structure is not held; check the "
        "constraints, loads and the coupled forces (an undamped soft plate: add analysis.rayleigh "
        "damping or a smaller time.window)",
        d, model_size_);
  return {};
}

void FemAdapter::write_restart(BinaryWriter& out) const {
  out.section("fem");
  std::ostringstream state;
  fem::write_state(state, solver_->save_state());  // the solver's own versioned format
  out.bytes(state.str());
  out.section("fem interfaces");
  for (const auto& i : interfaces_) {
    out.write(i.nodal_forces);
    out.write(i.tractions);
    out.write(static_cast<std::uint8_t>(i.has_forces));
    out.write(static_cast<std::uint8_t>(i.has_tractions));
  }
  out.section("fem interface work");
  for (const auto& i : interfaces_) i.audit.save(out);
}

void FemAdapter::read_restart(BinaryReader& in) {
  in.expect_section("fem");
  std::istringstream bytes(in.bytes());
  fem::SolverState s;
  try {
    s = fem::read_state(bytes);
  } catch (const fem::Error& e) {
    throw Error(in.source() + ": the FE state of '" + name_ + "': " + e.what());
  }
  const Eigen::Index dofs = solver_->displacement().size();
  for (const Eigen::VectorXd* v : {&s.displacement, &s.velocity, &s.acceleration})
    if (v->size() != dofs) in.fail(std::to_string(dofs) + " degrees of freedom (the same mesh)");
  in.expect_section("fem interfaces");
  for (auto& i : interfaces_) {
    in.read(i.nodal_forces);
    in.read(i.tractions);
    i.has_forces = in.get<std::uint8_t>() != 0;
    i.has_tractions = in.get<std::uint8_t>() != 0;
  }
  in.expect_section("fem interface work");
  for (auto& i : interfaces_) i.audit.load(in, "loads of interface '" + i.name + "'");
  solver_->restore_state(s);
  forces_pending_ = false;
  failure_log_.restored(*solver_);
}

void FemAdapter::write_output(const OutputFrame& frame) {
  const std::string file = fmt::format("{}_fem_{:06d}.vtu", frame.prefix, frame.index);
  std::vector<const fem::IndenterContact*> contacts;
  for (const auto& ind : indenters_) contacts.push_back(ind.contact);
  write_fem_vtu(*solver_, frame.vtk_directory / file, frame.vtk, contacts);
  files_ = {{"fem", file}};
  for (const auto& ind : indenters_) {  // the indenters' surfaces where they are
    if (!ind.has_surface) continue;
    const std::string f = fmt::format("{}_{}_{:06d}.vtp", frame.prefix, ind.name, frame.index);
    for (const auto& m : meshes_)
      if (m.mesh.name() == ind.name) write_indenter_vtp(frame.vtk_directory / f, m, *ind.contact, frame.vtk);
    files_.emplace_back(ind.name, f);
  }
  for (const auto& p : probes_)
    write_file_atomically(frame.vtk_directory.parent_path() / "probes" /
                              fmt::format("{}_{}_{:06d}.csv", frame.prefix, p.name(), frame.index),
                          p.csv(*solver_));
}

}  // namespace partita::adapters
