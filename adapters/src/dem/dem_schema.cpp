// The DEM adapter's schema: the keys of a DEM participant (`partita docs dem`), each with its
// type, unit, default and doc; the validation and the documentation both come from it.

#include "dem_adapter.hpp"

namespace partita::adapters {

using config::Spec;

namespace {

std::shared_ptr<Spec> make_spec() {
  auto interaction =
      std::make_shared<Spec>("interaction", "contact parameters of a pair of materials");
  interaction->strings("pair", "the two material names (the same name twice for like contacts)")
      .size(2)
      .required();
  interaction->real("friction", "Coulomb friction coefficient mu").non_negative().def(0.3);
  interaction->real("restitution", "normal coefficient of restitution e")
      .range(0.0, 1.0)
      .min(0.0, true)
      .def(0.5);
  interaction
      ->real("rolling_friction", "rolling friction coefficient mu_r (constant torque mu_r F_n R*)")
      .non_negative()
      .def(0.0);

  auto box = std::make_shared<Spec>("box", "an axis-aligned box");
  box->reals("origin", "lower corner").unit("m").size(3).required();
  box->reals("size", "edge lengths").unit("m").size(3).min(0.0, true).required();

  auto generate = std::make_shared<Spec>(
      "generate", "fill a box (or several) with a size distribution to a target porosity");
  generate->section("box", "the region to fill", box);
  generate->list("boxes",
                 "several regions, each filled alone to the porosity with the same distribution "
                 "(e.g. the cells of a cellular structure); box i uses the seed seed + i",
                 box);
  generate->one_of({"box", "boxes"});
  generate->reals("diameters", "particle diameters").unit("m").min(0.0, true).required();
  generate->reals("fractions", "share of each diameter (any positive scale; default: equal)")
      .min(0.0, true);
  generate->choice("basis", "fractions by number of particles or by mass", {"number", "mass"})
      .def("number");
  generate->real("porosity", "target porosity 1 - solid volume / box volume")
      .range(0.3, 1.0, true)
      .def(0.5);
  generate->integer("seed", "random seed (same seed, same packing)").min(0).def(1);
  generate
      ->real("max_particles",
             "refuse a packing estimated (box volume x (1 - porosity) / mean particle volume) "
             "above this many particles (a typing error in the box or diameters); raise it for "
             "larger runs")
      .positive()
      .def(5.0e6);

  auto particles =
      std::make_shared<Spec>("particles", "the particles: generated or read from a file");
  particles->string("material", "material name of the particles").required();
  particles->section("generate", "generate a packing", generate);
  particles->string(
      "file",
      "LAMMPS data file (id type diameter density x y z [+ Velocities]), relative to the case; "
      "each particle's mass follows the file's density where it differs from the material's "
      "(e.g. the final state a DEM run wrote with output: {particles_file: end})");
  particles->one_of({"generate", "file"});

  auto plane = std::make_shared<Spec>("plane", "an infinite plane");
  plane->reals("point", "a point on the plane").unit("m").size(3).required();
  plane->reals("normal", "normal pointing to the side where the particles are").size(3).required();

  auto wall = std::make_shared<Spec>("wall", "a rigid wall: a plane or the inside of a box");
  wall->string("name", "name used by the monitors (default: wall<i>)");
  wall->section("plane", "an infinite plane", plane);
  wall->section("box", "a box holding the particles inside", box);
  wall->strings("open", "box faces to leave open")
      .choices({"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"});
  wall->string("material", "material name").required();
  wall->reals("velocity", "prescribed translation velocity")
      .unit("m/s")
      .size(3)
      .def(std::vector<double>{0, 0, 0});
  wall->any("velocity_table", std::string("the velocity times a factor over time: ") +
                                  TimeTable::doc() + " (e.g. press, hold and release a lid)");
  auto servo = std::make_shared<Spec>(
      "servo",
      "a plane wall driven along its normal to a target force: after every step its velocity is "
      "clamp(gain (force - F_n), -max_velocity, max_velocity) along the normal, F_n the force "
      "the particles push it back with (e.g. a lid pressing a bed to a given load)");
  servo->real("force", "target normal force").unit("N").positive().required();
  servo->real("max_velocity", "largest speed of the wall (small against the bed's wave speed)")
      .unit("m/s")
      .positive()
      .required();
  servo->real("gain", "velocity per force error (default: max_velocity / force)")
      .unit("m/(s N)")
      .positive();
  wall->section("servo", "a plane wall pressed to a target force (not with velocity or "
                "velocity_table)", servo);
  wall->one_of({"plane", "box"});

  auto grid = std::make_shared<Spec>(
      "rectangle", "a flat rectangle z = origin.z, triangulated in 2 nx ny triangles");
  grid->reals("origin", "corner with the smallest x and y").unit("m").size(3).required();
  grid->reals("size", "edge lengths along x and y").unit("m").size(2).min(0.0, true).required();
  grid->integers("cells", "cells along x and y").size(2).min(1).required();
  grid->choice("facing", "the side the particles are on", {"down", "up"}).def("down");

  auto mesh =
      std::make_shared<Spec>("mesh", "a triangle mesh the particles touch; a coupling interface");
  mesh->string("name",
               "name: coupling meshes <name> (vertices) and <name>_centres (triangle centroids)")
      .required();
  mesh->string("stl", "STL file (ASCII or binary), relative to the case file");
  mesh->real("scale", "factor applied to the STL coordinates (e.g. 1.0e-3 for a file in mm)")
      .positive()
      .def(1.0);
  mesh->section("rectangle", "generated flat rectangle", grid);
  mesh->string("material", "material name").required();
  mesh->string("from",
               "participant.mesh of another participant (e.g. an FE interface face): its surface, "
               "handed over at set-up, becomes this contact mesh (follow its displacement through "
               "an exchange)");
  mesh->boolean("one_sided",
                "contacts from the outer side only, for the closed surface of a body (an FE "
                "surface taken with from:, an STL with outward normals): a face pushes along its "
                "outward normal, also a particle whose centre has passed behind it (less than its "
                "radius deep), which two-sided contacts would push on through a thin plate; "
                "edges and vertices touch from outside only (default false: two-sided, each "
                "contact along centre - closest point)");
  mesh->one_of({"stl", "rectangle", "from"});

  auto breakage = std::make_shared<Spec>(
      "breakage",
      "crushable particles (seed 001, eq. 2): a particle breaks when a contact's mean Hertz "
      "pressure reaches its strength sigma = sigma_lim,0 (d/d0)^(-3/m) (times a Weibull scatter)");
  breakage->real("limit_strength", "limit strength sigma_lim,0 of a particle of size d0")
      .unit("Pa")
      .positive()
      .required();
  breakage->real("reference_size", "reference diameter d0 of the limit strength")
      .unit("m")
      .positive()
      .required();
  breakage->real("weibull_modulus", "Weibull modulus m (size effect and scatter)")
      .positive()
      .required();
  breakage
      ->choice("scatter",
               "per-particle strength: weibull (drawn, modulus m, reproducible from the seed) or "
               "none (every particle at sigma_lim,0 (d/d0)^(-3/m))",
               {"weibull", "none"})
      .def("weibull");
  breakage->real("comminution_limit", "d_min: particles with a smaller diameter do not fragment")
      .unit("m")
      .positive()
      .required();
  breakage
      ->choice("below_limit",
               "what a particle smaller than comminution_limit does when a contact reaches its "
               "strength: unbreakable (nothing: it never breaks), powder (it is crushed to "
               "powder: removed, its mass and kinetic and contact energy counted in "
               "breakage.powder_mass and breakage.powder_energy; powder carries no load) or yield "
               "(it stays, unbreakable, and yields in its contacts with the structure's meshes and "
               "with other particles: the contact's mean pressure is held at its strength, the "
               "overlap beyond becomes permanent and its work joins damping_work; a fragment "
               "pinched between two closing faces or by its neighbours is flattened instead of "
               "storing the elastic energy of an overlap of its own size; against a mesh it "
               "yields until its centre reaches the face and is elastic beyond, and where a "
               "contact's pressure reaches 1.5 times its strength (pressed on there, against a "
               "plane, which stays elastic, or in a hard impact) or where two faces closer than "
               "its radius pinch it, it is crushed to powder, counted as above: it is not "
               "pressed through the surface)",
               {"unbreakable", "powder", "yield"})
      .def("unbreakable");
  breakage
      ->choice("pattern",
               "fragments inscribed in the broken particle: equal-4 (tetrahedron, 36 % of the "
               "mass), equal-6 (octahedron, 43 %), apollonian-14 (6 + 8, 52 %)",
               dem::FragmentPattern::names())
      .def("apollonian-14");
  breakage
      ->choice("mass",
               "the mass the fragments cannot hold: lost (counted) or restored to the fragments "
               "(counted)",
               {"lost", "restored"})
      .def("lost");
  breakage->integer("seed", "seed of the strengths and fragment orientations").min(0).def(1);
  breakage
      ->choice("lists",
               "how the neighbour lists take in a breakage's fragments: search (the next step "
               "searches every pair again, renumbers the particles when sort_interval asks at a "
               "build and computes the forces again) or local (a fragment's pairs are found "
               "among its parent's listed neighbours, the lists stay valid and the particles keep "
               "their order; each fragment starts with its parent's accelerations until the next "
               "force pass): the same physics, different rounding; local spares a crushing bed "
               "most of its neighbour searches",
               {"search", "local"})
      .def("search");

  auto s = std::make_shared<Spec>(
      "dem", "native DEM (solvers/dem): Hertz-Mindlin spheres, planes, triangle meshes");
  s->any("materials",
         "map of material name -> {youngs_modulus (Pa, required), poisson_ratio (required), "
         "density (kg/m^3, default 2500)}")
      .required();
  s->list("interactions",
          "contact parameters of each pair of materials that can touch: the particles' material "
          "with each wall's and mesh's, and with itself where two particles exist (or breakage "
          "makes fragments; a single particle needs no interaction with itself). A pair that can "
          "touch has no default: friction and restitution belong to the pair, not to either "
          "material",
          interaction)
      .required();
  s->choice("damping",
            "restitution model: calibrated (exact e for Hertz) or liggghts (the LIGGGHTS formula)",
            {"calibrated", "liggghts"})
      .def("calibrated");
  s->section("particles", "the particles", particles).required();
  s->list("walls", "rigid walls", wall);
  s->list("meshes", "triangle meshes (coupling interfaces)", mesh);
  s->reals("gravity", "gravitational acceleration")
      .unit("m/s^2")
      .size(3)
      .def(std::vector<double>{0, 0, -9.81});
  s->real("time_step_fraction",
          "time step as a fraction of the Rayleigh step of the smallest particle (default: "
          "chosen from the restitutions in use so that each is realised to 1 % for impacts up to "
          "1.6 % of the wave speed: 0.2 for e >= 0.9, 0.1 for 0.2 <= e < 0.9, 0.05 for "
          "0.15 <= e < 0.2, 0.02 below; 0.2 realises e = 0.1 about 2 % low and e = 0.3..0.7 up "
          "to 2.5 % high)")
      .range(0.0, 1.0)
      .min(0.0, true);
  s->real("skin", "Verlet skin (default: 10 % of the largest radius)").unit("m").non_negative();
  s->boolean("energy_accounting",
             "cumulative energies (monitors friction_work, damping_work, breakage_energy, "
             "stiffening_work, gravity_work, wall_work, <wall>.work, <mesh>.work, "
             "elastic_energy, energy_balance_error); costs ~55 % of the CPU of a DEM step on a "
             "settled bed (bench/README.md) (default false)");
  s->real("lost_margin",
          "a particle farther than this outside the domain's bounding box (particles at the "
          "start, box walls, the points of plane walls, meshes) stops the run as lost (default: "
          "the box's largest edge, at least 5 largest particle diameters)")
      .unit("m")
      .positive();
  s->integer("sort_interval",
             "renumber the particles in cell order at the first step and every N-th "
             "neighbour-list build (keeps neighbours close in memory; 0: never)")
      .min(0)
      .def(10);
  s->section("breakage", "crushable particles (off when absent)", breakage);
  s->integers("monitor_particles",
              "ids of particles whose position and velocity are monitor quantities "
              "particle.<id>.x|y|z [m] and particle.<id>.vx|vy|vz [m/s] (e.g. monitors: "
              "[{name: ball, quantities: [granules.particle.1.z]}]); ids as in the particle file, "
              "or 0, 1, ... in the order generated; a particle that breakage removed keeps its "
              "last values")
      .min(0);
  auto output = std::make_shared<Spec>("output", "files of this participant beyond the VTK series");
  output
      ->choice("particles_file",
               "the particles as a LAMMPS data file that particles: {file: ...} reads back bit "
               "for bit (positions, velocities, diameters, densities): none, end (DIR/"
               "<participant>.data after the last window, or where a signal stopped the run) or "
               "every-output (also DIR/particles/<participant>_<frame>.data at each output time)",
               {"none", "end", "every-output"})
      .def("none");
  s->section("output", "participant output", output);
  return s;
}

}  // namespace

std::shared_ptr<const config::Spec> DemAdapter::spec() {
  static const std::shared_ptr<const config::Spec> s = make_spec();
  return s;
}

// One entry of `materials` (a map name -> material, validated entry by entry).
std::shared_ptr<const config::Spec> DemAdapter::material_spec() {
  static const std::shared_ptr<const Spec> spec = [] {
    auto m = std::make_shared<Spec>("material",
                                    "bulk properties of a DEM material (particles, walls, meshes)");
    m->real("youngs_modulus", "Young's modulus E")
        .unit("Pa")
        .positive()
        .typical(config::kSolidModulusLow, config::kSolidModulusHigh, config::kSolidModulusWhat)
        .required();
    m->real("poisson_ratio", "Poisson's ratio nu").range(-1.0, 0.5, true).required();
    m->real("density", "mass density rho (used for particles)")
        .unit("kg/m^3")
        .positive()
        .typical(config::kSolidDensityLow, config::kSolidDensityHigh, config::kSolidDensityWhat)
        .def(2500.0);
    return m;
  }();
  return spec;
}

}  // namespace partita::adapters
