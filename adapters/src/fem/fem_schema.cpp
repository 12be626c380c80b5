// The FEM adapter's schema: the keys of a FEM participant (`partita docs fem`), each with its
// type, unit, default and doc; the validation and the documentation both come from it. The
// material's keys: fem_material.cpp; the panel's, the rupture's and the indenters': their files.

#include "fem_adapter.hpp"
#include "fem_material.hpp"
#include "fem_panel_config.hpp"
#include "fem_rupture.hpp"
#include "indenter_config.hpp"
#include "partita/interface/time_table.hpp"

namespace partita::adapters {

namespace {

using config::Spec;

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
  auto interior = std::make_shared<Spec>(
      "interior_face",
      "a face of the faces that two elements share (each once from either side, oriented out "
      "of its own element), for eroding contact: a coupling interface or an indenter on it "
      "touches a face only once erosion has exposed it (its element in, the element across "
      "eroded), so a granule or the bow that enters an eroded element's hole meets the faces "
      "around it");
  interior->string("name", "the face's name (not one the mesh has)").required();
  interior->strings("regions",
                    "only the faces of elements in these regions (default: every region)");
  mesh->list("interior_faces", "faces between elements, exposed by erosion", interior);

  auto constraint = std::make_shared<Spec>("constraint", "a Dirichlet condition on a node set");
  constraint
      ->string("set",
               "node set (box: all, xmin ... zmax; panel: all, outer, inner, xmin ... ymax, "
               "cell_<i>_<j>; Gmsh: physical group names)")
      .required();
  constraint->strings("fix", "components held at zero").choices(FemAdapter::kComponents);
  constraint->choice("component", "component of a prescribed displacement", FemAdapter::kComponents);
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
  interface->string("name", "interface name: meshes <name> (nodes), <name>_quadrature (quadrature points) and <name>_centres (writes 'attached' per triangle of <name>: 1 while its element is in and its face exposed: on the boundary, or, on a face of mesh.interior_faces, once the element across has eroded)")
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
  auto self = std::make_shared<Spec>(
      "self_contact",
      "node-to-face penalty contact of the body with itself over the listed faces; with "
      "erosion, the faces between elements (mesh.interior_faces) join once the element across "
      "has eroded (eroding single-surface contact: a torn plate folding onto a web, the faces "
      "around a crushed element closing its gap); central-difference analyses only");
  self->strings("faces",
                "the faces that may touch each other (their union), e.g. [outer, inner, cavity, "
                "exposed]")
      .required();
  self->real("penalty_factor",
             "k = factor E A_node / h per node (as an indenter's penalty); the default 0.1 is "
             "the scale explicit codes use for contact between deformable parts (LS-DYNA's "
             "SLSFAC)")
      .positive()
      .def(0.1);
  self->real("depth",
             "the deepest penetration caught, as a fraction of the element's thickness under "
             "the face (0 < depth < 1; deeper lies the plate's other side)")
      .positive()
      .def(0.5);
  s->section("self_contact", "contact of the body with itself (optional)", self);
  s->list("indenters",
          "rigid indenters in penalty contact with an FE face (part of this model's operator; a "
          "linear-elastic model keeps its fast K u in central difference, and takes the "
          "nonlinear path, element by element, in static and Newmark analyses)",
          indenter_spec());
  return s;
}

}  // namespace

std::shared_ptr<const config::Spec> FemAdapter::spec() {
  static const std::shared_ptr<const config::Spec> s = make_spec();
  return s;
}

}  // namespace partita::adapters
