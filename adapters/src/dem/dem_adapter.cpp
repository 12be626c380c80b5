#include "dem_adapter.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

#include "partita/adapters/dem_output.hpp"
#include "partita/coupling/time_window.hpp"
#include "partita/dem/breakage.hpp"
#include "partita/dem/wall_servo.hpp"
#include "partita/dem/error.hpp"
#include "partita/dem/grading.hpp"
#include "partita/dem/lammps_data.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"
#include "partita/interface/stl.hpp"
#include "partita/interface/time_table.hpp"

namespace partita::adapters {

namespace {

using config::Node;
using config::Spec;

// One entry of `materials` (a map name -> material, validated entry by entry).
std::shared_ptr<const Spec> material_spec() {
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
               "strength: unbreakable (nothing: it never breaks) or powder (it is crushed to "
               "powder: removed, its mass and kinetic and contact energy counted in "
               "breakage.powder_mass and breakage.powder_energy; powder carries no load)",
               {"unbreakable", "powder"})
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

Mesh rectangle(const Node& g, const std::string& name) {
  const Eigen::Vector3d o = g.vec3("origin");
  const auto size = g.reals("size");
  const auto cells = g.integers("cells");
  const long nx = cells[0], ny = cells[1];
  if (2.0 * static_cast<double>(nx) * static_cast<double>(ny) > 2.0e7)
    g["cells"].fail(
        fmt::format("{} x {} cells make {:.3g} triangles, more than 2e7; check the counts", nx, ny,
                    2.0 * static_cast<double>(nx) * static_cast<double>(ny)));
  Mesh::Points p((nx + 1) * (ny + 1), 3);
  for (long j = 0; j <= ny; ++j)
    for (long i = 0; i <= nx; ++i)
      p.row(j * (nx + 1) + i) << o.x() + size[0] * static_cast<double>(i) / static_cast<double>(nx),
          o.y() + size[1] * static_cast<double>(j) / static_cast<double>(ny), o.z();
  Mesh::Triangles t(2 * nx * ny, 3);
  const bool down = g.string("facing") == "down";
  long k = 0;
  for (long j = 0; j < ny; ++j)
    for (long i = 0; i < nx; ++i) {
      const int a = static_cast<int>(j * (nx + 1) + i), b = a + 1, c = a + static_cast<int>(nx) + 1,
                d = c + 1;
      if (down) {
        t.row(k++) << a, d, b;
        t.row(k++) << a, c, d;
      } else {
        t.row(k++) << a, b, d;
        t.row(k++) << a, d, c;
      }
    }
  return Mesh(name, p, t);
}

}  // namespace

std::shared_ptr<const config::Spec> DemAdapter::spec() {
  static const std::shared_ptr<const config::Spec> s = make_spec();
  return s;
}

std::unique_ptr<Solver> DemAdapter::create(const SolverContext& context) {
  return std::make_unique<DemAdapter>(context);
}

DemAdapter::DemAdapter(const SolverContext& context)
    : name_(context.name), output_dir_(context.output_dir) {
  const Node& c = context.config;
  auto resolve = [&](const std::filesystem::path& f) {
    return f.is_relative() ? context.case_dir / f : f;
  };
  try {
    // Materials: a map name -> properties, each validated against the material spec.
    std::map<std::string, int> materials;
    std::vector<std::string> material_names;
    const Node mats = c["materials"];
    if (!mats.is_map() || mats.size() == 0)
      mats.fail(
          "expected a map of materials, e.g. materials: {glass: {youngs_modulus: 200 MPa, "
          "poisson_ratio: "
          "0.23, density: 400}}; found " +
          mats.describe());
    for (const std::string& m : mats.keys()) {
      const Node mn = mats[m].validated(material_spec());
      dem::Material mat{mn.real("youngs_modulus"), mn.real("poisson_ratio"), mn.real("density")};
      materials[m] = system_.add_material(mat);
      material_names.push_back(m);
    }
    auto material_id = [&](const Node& n) {
      const std::string m = n.as_string();
      auto it = materials.find(m);
      if (it == materials.end())
        n.fail("unknown material '" + m + "'; materials: " + join_names(material_names) +
               did_you_mean(m, material_names));
      return it->second;
    };

    for (const Node& in : c["interactions"].items()) {
      const auto pair = in["pair"].items();
      dem::Interaction it{in.real("friction"), in.real("restitution"), in.real("rolling_friction")};
      system_.add_interaction(material_id(pair[0]), material_id(pair[1]), it);
    }
    system_.set_damping_model(c.string("damping") == "liggghts" ? dem::DampingModel::liggghts
                                                                : dem::DampingModel::calibrated);
    system_.set_gravity(c.vec3("gravity"));
    if (c.has("skin")) system_.set_skin(c.real("skin"));
    system_.set_energy_tracking(c.has("energy_accounting") && c.boolean("energy_accounting"));
    system_.set_sort_interval(static_cast<int>(c.integer("sort_interval")));
    particles_file_ = c["output"].string("particles_file");
    time_step_fraction_auto_ = !c.has("time_step_fraction");
    if (!time_step_fraction_auto_) time_step_fraction_ = c.real("time_step_fraction");

    // Particles.
    const Node pn = c["particles"];
    const int pm = material_id(pn["material"]);
    if (pn.has("generate")) {
      const Node g = pn["generate"];
      std::vector<Node> regions;
      if (g.has("box"))
        regions.push_back(g["box"]);
      else
        for (const Node& b : g["boxes"].items()) regions.push_back(b);
      dem::PackingSpec ps;
      ps.diameters = g.reals("diameters");
      // A diameter must fit the smallest box it fills and be resolved by the positions' round-off
      // there (1e-12 of the box): a length written without its unit is in metres.
      for (std::size_t i = 0; i < ps.diameters.size(); ++i) {
        const Node d = g["diameters"][i];
        const bool bare = d.is_scalar() && config::parse_quantity(d.yaml().Scalar(), "");
        for (const Node& b : regions) {
          const Eigen::Vector3d size = b.vec3("size");
          if (ps.diameters[i] > size.minCoeff())
            d.fail(fmt::format(
                "diameter {:.6g} m{} is larger than the box it fills ({:.4g} x {:.4g} x {:.4g} "
                "m, line {}){}",
                ps.diameters[i], bare ? " as read (a number without a unit is in m)" : "",
                size.x(), size.y(), size.z(), b.location().line,
                bare ? fmt::format("; did you mean {} mm? Write the unit: {} mm",
                                   d.yaml().Scalar(), d.yaml().Scalar())
                     : std::string()));
          if (ps.diameters[i] < 1e-12 * size.maxCoeff())
            d.fail(fmt::format(
                "diameter {:.6g} m is below the round-off of positions in a box of {:.4g} m "
                "(1e-12 of it): contacts cannot be resolved; check the value and its unit",
                ps.diameters[i], size.maxCoeff()));
        }
      }
      ps.fractions =
          g.has("fractions") ? g.reals("fractions") : std::vector<double>(ps.diameters.size(), 1.0);
      if (ps.fractions.size() != ps.diameters.size())
        g["fractions"].fail("expected one fraction per diameter (" +
                            std::to_string(ps.diameters.size()) + "), found " +
                            std::to_string(ps.fractions.size()));
      ps.basis = g.string("basis") == "mass" ? dem::PackingSpec::Basis::mass
                                             : dem::PackingSpec::Basis::number;
      ps.porosity = g.real("porosity");
      // N = (1 - porosity) V_box / V_mean, V_mean the mean particle volume of the distribution
      // (by number: sum f_i V_i / sum f_i; by mass = by volume: 1 / sum (f_i / sum f) / V_i).
      {
        const double pi = 3.14159265358979323846;
        double fsum = 0.0, by_number = 0.0, inverse = 0.0;
        for (std::size_t i = 0; i < ps.diameters.size(); ++i) fsum += ps.fractions[i];
        for (std::size_t i = 0; i < ps.diameters.size(); ++i) {
          const double v = pi / 6.0 * std::pow(ps.diameters[i], 3);
          by_number += ps.fractions[i] / fsum * v;
          inverse += ps.fractions[i] / fsum / v;
        }
        const double v_mean = ps.basis == dem::PackingSpec::Basis::mass ? 1.0 / inverse : by_number;
        double volume = 0.0;
        for (const Node& b : regions) volume += b.vec3("size").prod();
        const double estimate = (1.0 - ps.porosity) * volume / v_mean;
        const double limit = g.real("max_particles");
        if (!(estimate <= limit))
          g.fail(fmt::format(
              "{} ({:.4g} m^3 in all) filled to porosity {:.3g} holds about {:.3g} "
              "particles, more than max_particles = {:.3g}; check the box sizes and diameters "
              "(units: a box of 5012 m instead of 0.05 m is a typical slip), or raise "
              "max_particles",
              regions.size() == 1 ? std::string("this box") : fmt::format("these {} boxes", regions.size()),
              volume, ps.porosity, estimate, limit));
        if (estimate > 1e5)
          log::get("adapters")
              ->info("dem '{}': generating about {:.3g} particles (this may take a while)", name_,
                     estimate);
      }
      // progress of a long generation, every 5 s
      auto clock = std::chrono::steady_clock::now();
      ps.progress = [&, name = name_](int sweep, double overlap) {
        const auto now = std::chrono::steady_clock::now();
        if (now - clock < std::chrono::seconds(5)) return;
        clock = now;
        log::get("adapters")
            ->info(
                "dem '{}': generating the packing: sweep {}, largest overlap {:.3g} R_min "
                "(target {:.3g})",
                name, sweep, overlap, ps.max_overlap);
      };
      const auto seed = static_cast<std::uint64_t>(g.integer("seed"));
      for (std::size_t b = 0; b < regions.size(); ++b) {
        ps.lo = regions[b].vec3("origin");
        ps.hi = ps.lo + regions[b].vec3("size");
        ps.seed = seed + b;
        dem::Packing packing;
        try {
          packing = dem::PackingGenerator::generate(ps);
        } catch (const dem::Error& e) {
          regions[b].fail(std::string("cannot generate the packing: ") + e.what());
        }
        system_.add_particles(packing.positions, packing.radii, pm);
        log::get("adapters")
            ->info("dem '{}': generated {} particles{}, porosity {:.3f}, largest overlap {:.2e} m",
                   name_, packing.radii.size(),
                   regions.size() == 1 ? std::string() : fmt::format(" in box {}", b + 1),
                   packing.porosity, packing.max_overlap);
      }
    } else {
      const std::filesystem::path f = resolve(pn.string("file"));
      if (!std::filesystem::exists(f))
        pn["file"].fail("particle file '" + f.string() + "' does not exist");
      const dem::LammpsData d = dem::LammpsData::read(f.string());
      const double rho = system_.contact_model().material(pm).density;
      for (std::size_t i = 0; i < d.size(); ++i) {
        const double r = d.diameter[i] / 2;
        const std::size_t k = system_.add_particle(d.position[i], r, pm, d.velocity[i],
                                                   d.angular_velocity[i], d.id[i]);
        if (d.density[i] != rho) {  // the file's density sets the mass (as add_particle would)
          const double m = d.density[i] * 4.0 / 3.0 * std::numbers::pi * r * r * r;
          system_.set_particle_mass(k, m, 0.4 * m * r * r);
        }
      }
    }

    // Walls.
    int wi = 0;
    // the box of the bounded geometry (box walls, meshes): particles absurdly far from it are
    // refused at set-up (a unit slip in a particle file)
    Eigen::Vector3d bound_lo = Eigen::Vector3d::Constant(1e300);
    Eigen::Vector3d bound_hi = Eigen::Vector3d::Constant(-1e300);
    for (const Node& w : c["walls"].items()) {
      Wall wall;
      wall.name = w.has("name") ? w.string("name") : "wall" + std::to_string(wi);
      ++wi;
      const int mid = material_id(w["material"]);
      const Eigen::Vector3d v = w.vec3("velocity");
      if (w.has("plane")) {
        const Eigen::Vector3d n = w["plane"].vec3("normal");
        if (!(n.norm() > 0)) w["plane"]["normal"].fail("the normal must not be zero");
        wall.id = system_.add_plane(w["plane"].vec3("point"), n.normalized(), mid, v);
        // an infinite plane bounds the domain on one side: its point counts (a sphere dropped
        // on a plane has a domain from the plane up to the sphere)
        domain_lo_ = domain_lo_.cwiseMin(w["plane"].vec3("point"));
        domain_hi_ = domain_hi_.cwiseMax(w["plane"].vec3("point"));
      } else {
        unsigned faces = 0b111111;
        if (w.has("open"))
          for (const std::string& f : w.strings("open"))
            faces &= ~(1u << static_cast<unsigned>(std::find(kFaces.begin(), kFaces.end(), f) -
                                                   kFaces.begin()));
        const Eigen::Vector3d lo = w["box"].vec3("origin");
        wall.id = system_.add_box(lo, lo + w["box"].vec3("size"), mid, faces);
        wall.faces = faces;
        domain_lo_ = domain_lo_.cwiseMin(lo);
        domain_hi_ = domain_hi_.cwiseMax(lo + w["box"].vec3("size"));
        bound_lo = bound_lo.cwiseMin(lo);
        bound_hi = bound_hi.cwiseMax(lo + w["box"].vec3("size"));
        if (v.norm() > 0) system_.set_wall_velocity(wall.id, v);
      }
      if (w.has("velocity_table")) {
        wall.velocity = v;
        wall.table = TimeTable::from_node(w["velocity_table"]);
        wall.moving = true;
      }
      if (w.has("servo")) {
        const Node s = w["servo"];
        if (!w.has("plane"))
          s.fail("a servo drives a plane wall along its normal; this wall is a box (use a "
                 "plane wall, e.g. a lid)");
        if (w.has("velocity_table") || v.norm() > 0)
          s.fail("a servo wall sets its own velocity: remove velocity / velocity_table");
        dem::WallServoParameters sp;
        sp.wall = wall.id;
        sp.normal = w["plane"].vec3("normal").normalized();
        sp.force = s.real("force");
        sp.max_velocity = s.real("max_velocity");
        sp.gain = s.has("gain") ? s.real("gain") : sp.max_velocity / sp.force;
        system_.add_hook(std::make_unique<dem::WallServo>(sp));
      }
      walls_.push_back(wall);
    }

    // Meshes: the coupling interfaces.
    for (const Node& m : c["meshes"].items()) {
      CouplingMesh cm;
      cm.name = m.string("name");
      for (const auto& other : meshes_dem_)
        if (other.name == cm.name) m["name"].fail("mesh name '" + cm.name + "' is used twice");
      Mesh mesh;
      if (m.has("from")) {  // built when the core hands the surface over (receive_mesh)
        for (const auto& r : requests_)
          if (r.name == cm.name) m["name"].fail("mesh name '" + cm.name + "' is used twice");
        requests_.push_back(MeshRequest{cm.name, m.string("from"), m["from"]});
        request_materials_.push_back(material_id(m["material"]));
        continue;
      }
      if (m.has("stl")) {
        const std::filesystem::path f = resolve(m.string("stl"));
        std::vector<std::string> warnings;
        try {
          mesh = read_stl(f, cm.name, m.real("scale"), &warnings);
        } catch (const Error& e) {
          m["stl"].fail(e.what());
        }
        // The contacts are two-sided (a sphere touches a triangle from either side, pushed along
        // centre - closest point): the vertex order decides only for a centre on the triangle.
        for (const std::string& w : warnings)
          log::get("adapters")
              ->warn(
                  "dem '{}', mesh '{}': {} (the DEM's mesh contacts are two-sided: the vertex "
                  "order matters only where a sphere's centre reaches the triangle's plane, which "
                  "then pushes it to the side of the right-hand-rule normal)",
                  name_, cm.name, w);
      } else {
        mesh = rectangle(m["rectangle"], cm.name);
      }
      add_coupling_mesh(cm.name, mesh, material_id(m["material"]));
    }
    // Every pair that can touch needs an interaction: particles with walls and meshes, and with
    // each other where two particles exist (or fragments will: breakage). A single particle never
    // touches itself, so its material needs no interaction with itself. (No default for a pair
    // that can touch: friction and restitution belong to the pair, not to either material, and a
    // default would give a bed contact parameters nobody chose.)
    std::vector<int> partners;
    if (system_.particle_count() >= 2 || c.has("breakage")) partners.push_back(pm);
    for (const Node& w : c["walls"].items()) partners.push_back(material_id(w["material"]));
    for (const Node& m : c["meshes"].items()) partners.push_back(material_id(m["material"]));
    for (int b : partners)
      if (!system_.contact_model().has_interaction(pm, b)) {
        const std::string& na = material_names[static_cast<std::size_t>(pm)];
        const std::string& nb = material_names[static_cast<std::size_t>(b)];
        const std::string why =
            b != pm ? "which can touch"
            : system_.particle_count() >= 2
                ? fmt::format("which can touch: the {} particles are of material '{}'",
                              system_.particle_count(), na)
                : "which can touch: breakage makes fragments of the particle";
        c["interactions"].fail("no interaction between materials '" + na + "' and '" + nb +
                               "', " + why + "; add {pair: [" + na + ", " + nb +
                               "], friction: 0.3, restitution: 0.5}");
      }
    if (c.has("breakage")) add_breakage(c["breakage"]);
    if (c.has("monitor_particles")) {
      const dem::Particles& p = system_.particles();
      const Node ids = c["monitor_particles"];
      const std::vector<long> want = c.integers("monitor_particles");
      for (std::size_t k = 0; k < want.size(); ++k) {
        const auto it = std::find(p.id.begin(), p.id.end(), static_cast<std::int64_t>(want[k]));
        if (it == p.id.end()) {
          const auto [lo, hi] = std::minmax_element(p.id.begin(), p.id.end());
          (ids.is_sequence() ? ids[k] : ids)
              .fail(fmt::format("no particle has the id {}; the {} particles have ids {} .. {}",
                                want[k], p.size(), p.size() ? *lo : 0, p.size() ? *hi : 0));
        }
        tracked_.push_back(want[k]);
        tracked_index_.push_back(static_cast<std::size_t>(it - p.id.begin()));
        tracked_last_.push_back({});
      }
    }
    // Validate the set-up now (interactions of every pair in use, the Rayleigh step).
    (void)system_.rayleigh_time_step();
    if (time_step_fraction_auto_) time_step_fraction_ = system_.time_step_fraction();

    // A particle absurdly far from the box walls and meshes (more than kAbsurdFactor times their
    // box's largest edge, at least 5 particle diameters, outside it): a unit slip in a particle
    // file (880 m for 0.88 m), refused before the run rather than left to the neighbour grid.
    for (const auto& m : meshes_dem_)
      for (Eigen::Index i = 0; i < m.reference.rows(); ++i) {
        bound_lo = bound_lo.cwiseMin(m.reference.row(i).transpose());
        bound_hi = bound_hi.cwiseMax(m.reference.row(i).transpose());
      }
    if ((bound_lo.array() <= bound_hi.array()).all()) {
      double d_max = 0.0;
      for (const double r : system_.particles().radius) d_max = std::max(d_max, 2.0 * r);
      const double far =
          kAbsurdFactor * std::max((bound_hi - bound_lo).maxCoeff(), kLostDiameters * d_max);
      const dem::Particles& p = system_.particles();
      for (std::size_t i = 0; i < p.size(); ++i) {
        const Eigen::Vector3d& x = p.position[i];
        const double out = std::max((bound_lo - x).maxCoeff(), (x - bound_hi).maxCoeff());
        if (out > far)
          pn[pn.has("file") ? "file" : "generate"].fail(fmt::format(
              "particle id {} (index {}) at ({:.6g}, {:.6g}, {:.6g}) m lies {:.4g} m outside the "
              "domain of the walls and meshes [{:.4g} {:.4g} {:.4g}] .. [{:.4g} {:.4g} {:.4g}] "
              "m, more than {:g} times its size: check the units of the particle positions (m; "
              "e.g. 880 for 0.88) and the walls",
              p.id[i], i, x.x(), x.y(), x.z(), out, bound_lo.x(), bound_lo.y(), bound_lo.z(),
              bound_hi.x(), bound_hi.y(), bound_hi.z(), kAbsurdFactor));
      }
    }

    // The domain whose bounding box a particle must not leave by more than lost_margin.
    for (const auto& p : system_.particles().position) {
      domain_lo_ = domain_lo_.cwiseMin(p);
      domain_hi_ = domain_hi_.cwiseMax(p);
    }
    for (const auto& m : meshes_dem_)
      for (Eigen::Index i = 0; i < m.reference.rows(); ++i) {
        domain_lo_ = domain_lo_.cwiseMin(m.reference.row(i).transpose());
        domain_hi_ = domain_hi_.cwiseMax(m.reference.row(i).transpose());
      }
    lost_margin_given_ = c.has("lost_margin");
    lost_margin_ = lost_margin_given_ ? c.real("lost_margin") : default_lost_margin();
  } catch (const dem::Error& e) {
    c.fail(std::string("DEM model of participant '") + context.name + "': " + e.what());
  }
  // (meshes taken from other participants arrive later, through receive_mesh(): counted here)
  log::get("adapters")
      ->info(
          "dem '{}': {} particles, {} walls, {} meshes{}, Rayleigh step {:.3e} s, time step "
          "{:.3e} s",
          name_, system_.particle_count(), walls_.size(), meshes_dem_.size() + requests_.size(),
          requests_.empty() ? std::string()
                            : fmt::format(" ({} handed over by other participants)",
                                          requests_.size()),
          system_.rayleigh_time_step(), stable_time_step());
}

void DemAdapter::add_breakage(const config::Node& b) {
  dem::BreakageParameters p;
  p.limit_strength = b.real("limit_strength");
  p.reference_size = b.real("reference_size");
  p.weibull_modulus = b.real("weibull_modulus");
  p.scatter = b.string("scatter") == "weibull";
  p.comminution_limit = b.real("comminution_limit");
  p.powder = b.string("below_limit") == "powder";
  p.pattern = dem::FragmentPattern::named(b.string("pattern")).kind();
  p.restore_mass = b.string("mass") == "restored";
  p.seed = static_cast<std::uint64_t>(b.integer("seed"));
  breakage_ = system_.add_hook(std::make_unique<dem::Breakage>(p));
  double d_max = 0.0;
  for (double r : system_.particles().radius) d_max = std::max(d_max, 2.0 * r);
  if (p.comminution_limit > d_max)
    log::get("adapters")
        ->warn(
            "dem '{}': breakage.comminution_limit {:.4g} m is above the largest particle "
            "diameter {:.4g} m: nothing can break",
            name_, p.comminution_limit, d_max);
}

const dem::Breakage* DemAdapter::breakage() const {
  return breakage_ < 0 ? nullptr : &static_cast<const dem::Breakage&>(system_.hook(breakage_));
}

std::size_t DemAdapter::find(std::string_view mesh, bool* centres) const {
  for (std::size_t k = 0; k < meshes_dem_.size(); ++k) {
    const auto& m = meshes_dem_[k];
    if (mesh == m.name || mesh == m.name + "_centres") {
      *centres = mesh != m.name;
      return k;
    }
  }
  throw Error("dem '" + name_ + "' has no mesh '" + std::string(mesh) + "'");
}

void DemAdapter::read(std::string_view mesh, std::string_view data, const Eigen::MatrixXd& values) {
  bool centres = false;
  CouplingMesh& cm = meshes_dem_[find(mesh, &centres)];
  if (centres && data == "attached") {
    for (Eigen::Index t = 0; t < values.rows(); ++t)
      system_.set_triangle_active(cm.id, static_cast<int>(t), values(t, 0) >= 0.5);
    return;
  }
  if (centres || data != "displacement")
    throw Error("dem '" + name_ + "' reads 'displacement' on mesh '" + cm.name +
                "' and 'attached' on '" + cm.name + "_centres', not '" + std::string(data) +
                "' on '" + std::string(mesh) + "'");
  // x = X + d: the vertices follow the other side's displacement (no allocation: same size).
  cm.positions = cm.reference + values;
  system_.set_vertex_positions(cm.id, cm.positions);
}

void DemAdapter::write(std::string_view mesh, std::string_view data, Eigen::MatrixXd& values) {
  bool centres = false;
  const CouplingMesh& cm = meshes_dem_[find(mesh, &centres)];
  if (!centres) {
    if (data != "force")
      throw Error("dem '" + name_ + "' writes only 'force' on mesh '" + cm.name + "'");
    values = system_.vertex_forces(cm.id);
    return;
  }
  const Eigen::MatrixX3d& f = system_.triangle_forces(cm.id);
  if (data == "force") {
    values = f;
  } else if (data == "traction") {
    // t_i = f_i / A_i (seed 000, Algorithm 1), with the reference areas: column by column
    // (contiguous, two divisions per instruction; the same quotients as row by row)
    values.resize(f.rows(), 3);
    values.array() = f.array().colwise() / cm.areas.array();
  } else {
    throw Error("dem '" + name_ + "' writes 'force' and 'traction' on mesh '" + cm.name +
                "_centres', not '" + std::string(data) + "'");
  }
}

double DemAdapter::stable_time_step() const {
  // dt_R is a minimum over the particles (O(N) square roots): recomputed only when the particle
  // set changed (breakage adds fragments), not at every step that asks for it.
  // (Restoring a checkpoint or a restart file resets stable_for_count_.)
  if (system_.particle_count() != stable_for_count_ || time_step_fraction_ != stable_fraction_) {
    stable_ = time_step_fraction_ * system_.rayleigh_time_step();
    stable_for_count_ = system_.particle_count();
    stable_fraction_ = time_step_fraction_;
  }
  return stable_;
}

void DemAdapter::advance(double dt) {
  // walls with a velocity table move with the factor at the middle of the step (exact
  // displacement where the step lies within one row interval of the table)
  for (const auto& w : walls_)
    if (w.moving) system_.set_wall_velocity(w.id, w.velocity * w.table(system_.time() + 0.5 * dt));
  // Fragments lower the stable step. Between windows the core follows it (auto substeps) or
  // stops with the key to change (a fixed count); within a window, a step that breakage made
  // too long is split here into as many equal steps as the new stable step needs.
  int parts = 1;
  if (breakage_ >= 0) {
    const double stable = stable_time_step();
    if (coupling::TimeWindow::longer_than(dt, stable))
      parts = coupling::TimeWindow::substeps_for(dt, stable);
  }
  try {
    for (int k = 0; k < parts; ++k) system_.step(dt / parts);
  } catch (const dem::Error& e) {
    throw Error("dem '" + name_ + "' at t = " + fmt::format("{:.6g}", system_.time()) +
                " s: " + e.what());
  }
  // the work the meshes' motion did on the particles over this step (no allocation: same sizes)
  // (no allocation: same sizes)
  for (auto& cm : meshes_dem_) cm.audit.motion_step(cm.positions, system_.vertex_forces(cm.id));
}

std::optional<double> DemAdapter::interface_work(std::string_view mesh) const {
  bool centres = false;
  const CouplingMesh& cm = meshes_dem_[find(mesh, &centres)];
  // what M_centres reads ("attached") moves nothing: the motion's work is M's alone (counted
  // once when a case exchanges on both)
  if (centres) return std::nullopt;
  return cm.audit.work();
}

void DemAdapter::save_checkpoint() {
  checkpoint_ = system_.save_state();
  for (auto& cm : meshes_dem_) cm.audit.save_checkpoint();
  has_checkpoint_ = true;
}

void DemAdapter::restore_checkpoint() {
  if (!has_checkpoint_)
    throw Error("dem '" + name_ + "': restore_checkpoint() before save_checkpoint()");
  system_.restore_state(checkpoint_);
  for (auto& cm : meshes_dem_) cm.audit.restore_checkpoint();
  stable_for_count_ = kNoCount;
}

void DemAdapter::write_output(const OutputFrame& frame) {
  files_.clear();
  const std::string pfile = fmt::format("{}_particles_{:06d}.vtp", frame.prefix, frame.index);
  write_particles_vtp(system_, frame.vtk_directory / pfile, frame.vtk);
  files_.emplace_back("particles", pfile);
  for (const auto& m : meshes_dem_) {
    const std::string mfile = fmt::format("{}_{}_{:06d}.vtp", frame.prefix, m.name, frame.index);
    write_mesh_vtp(system_, m.id, frame.vtk_directory / mfile, frame.vtk);
    files_.emplace_back(m.name, mfile);
  }
  if (breakage_ >= 0) write_grading(frame);
  if (particles_file_ == "every-output") {
    const std::filesystem::path dir = frame.vtk_directory.parent_path() / "particles";
    std::filesystem::create_directories(dir);
    write_particles_file(dir / fmt::format("{}_{:06d}.data", frame.prefix, frame.index));
  }
}

void DemAdapter::finalize() {
  if (particles_file_ != "none") write_particles_file(output_dir_ / (name_ + ".data"));
}

void DemAdapter::write_particles_file(const std::filesystem::path& file) const {
  std::vector<double> density;
  for (int m = 0; m < system_.contact_model().material_count(); ++m)
    density.push_back(system_.contact_model().material(m).density);
  try {
    dem::LammpsData::of(system_.particles(), density)
        .write(file.string(),
               fmt::format("partita DEM '{}' at t = {:.17g} s", name_, system_.time()));
  } catch (const dem::Error& e) {
    throw Error("dem '" + name_ + "': " + e.what());
  }
}

// Grading at each output time: rows time, diameter, mass fraction passing, appended to
// DIR/<participant>_grading.csv (DIR the run's output folder, the parent of vtk/).
void DemAdapter::write_grading(const OutputFrame& frame) const {
  const std::filesystem::path file =
      frame.vtk_directory.parent_path() / (frame.prefix + "_grading.csv");
  const bool header = frame.index == 0 || !std::filesystem::exists(file);
  std::ofstream out(file, header ? std::ios::trunc : std::ios::app);
  if (!out) throw Error("dem '" + name_ + "': cannot write the grading to " + file.string());
  if (header) out << "time_s,diameter_m,passing\n";
  for (const dem::Grading::Point& g : dem::Grading::cumulative(system_.particles()))
    out << fmt::format("{:.9g},{:.9g},{:.9g}\n", frame.time, g.size, g.passing);
}

void DemAdapter::write_restart(BinaryWriter& out) const {
  out.section("dem");
  std::ostringstream state;
  system_.write_state(state);  // the DEM's own versioned format: particles with ids, contact
                               // histories, walls, mesh vertices, hooks' counters and RNG state
  out.bytes(state.str());
  out.section("dem interface work");
  for (const auto& cm : meshes_dem_) cm.audit.save(out);
}

void DemAdapter::read_restart(BinaryReader& in) {
  in.expect_section("dem");
  std::istringstream state(in.bytes());
  try {
    system_.read_state(state);
    stable_for_count_ = kNoCount;
  } catch (const dem::Error& e) {
    throw Error(in.source() + ": the DEM state of '" + name_ + "': " + e.what());
  }
  // a state whose particles are not finite or lie beyond the domain (a damaged or foreign file)
  // is refused here, with the particle, rather than by the neighbour grid at the first step
  if (const std::string astray = particle_astray(true); !astray.empty())
    throw Error(in.source() + ": the DEM state of '" + name_ + "' cannot be resumed: " + astray);
  in.expect_section("dem interface work");
  for (auto& cm : meshes_dem_) cm.audit.load(in, "vertices of mesh '" + cm.name + "'");
}

void DemAdapter::add_coupling_mesh(const std::string& name, const Mesh& mesh, int material) {
  CouplingMesh cm;
  cm.name = name;
  cm.reference = mesh.points();
  cm.positions = mesh.points();
  cm.areas = mesh.triangle_areas();
  cm.id = system_.add_mesh(mesh.points(), mesh.triangles(), material);
  cm.audit = InterfaceWork::motion(mesh.points(), system_.vertex_forces(cm.id));
  InterfaceMesh vertices;
  vertices.mesh = Mesh(name, mesh.points(), mesh.triangles());
  vertices.reads.push_back(DataSpec{"displacement", 3, "m", DataKind::intensive});
  vertices.writes.push_back(DataSpec{"force", 3, "N", DataKind::extensive});
  InterfaceMesh centres;
  centres.mesh = Mesh(name + "_centres", mesh.triangle_centroids());
  centres.mesh.set_weights(cm.areas);  // each centre stands for its triangle's area
  centres.writes.push_back(DataSpec{"force", 3, "N", DataKind::extensive});
  centres.writes.push_back(DataSpec{"traction", 3, "Pa", DataKind::intensive});
  // a triangle whose value is below 1/2 leaves the contacts (its surface has gone: the face of
  // an eroded FE element, FemAdapter's N_centres)
  centres.reads.push_back(DataSpec{"attached", 1, "", DataKind::intensive});
  meshes_.push_back(std::move(vertices));
  meshes_.push_back(std::move(centres));
  for (Eigen::Index i = 0; i < cm.reference.rows(); ++i) {
    domain_lo_ = domain_lo_.cwiseMin(cm.reference.row(i).transpose());
    domain_hi_ = domain_hi_.cwiseMax(cm.reference.row(i).transpose());
  }
  meshes_dem_.push_back(std::move(cm));
  // the mesh's material may be a new partner with a lower restitution
  if (time_step_fraction_auto_) time_step_fraction_ = system_.time_step_fraction();
}

void DemAdapter::receive_mesh(const std::string& name, const Mesh& mesh) {
  for (std::size_t k = 0; k < requests_.size(); ++k)
    if (requests_[k].name == name) {
      try {
        add_coupling_mesh(name, mesh, request_materials_[k]);
      } catch (const dem::Error& e) {
        requests_[k].where.fail(std::string("cannot use this surface as a contact mesh: ") +
                                e.what());
      }
      if (!lost_margin_given_) lost_margin_ = default_lost_margin();
      return;
    }
  throw Error("dem '" + name_ + "' asked for no mesh '" + name + "'");
}

double DemAdapter::default_lost_margin() const {
  double d_max = 0.0;
  for (const double r : system_.particles().radius) d_max = std::max(d_max, 2.0 * r);
  return std::max((domain_hi_ - domain_lo_).maxCoeff(), kLostDiameters * d_max);
}

std::string DemAdapter::check_state() const { return particle_astray(false); }

std::string DemAdapter::particle_astray(bool restored) const {
  // the first particle (lowest index) that is not finite or lies beyond the margin, if any
  const std::ptrdiff_t astray = system_.first_particle_astray(domain_lo_, domain_hi_, lost_margin_);
  if (astray < 0) return {};
  const dem::Particles& p = system_.particles();
  const auto i = static_cast<std::size_t>(astray);
  if (restored)
    return fmt::format(
        "particle id {} (index {}) at ({:.6g}, {:.6g}, {:.6g}) m with velocity ({:.6g}, {:.6g}, "
        "{:.6g}) m/s is not finite or lies outside the domain [{:.4g} {:.4g} {:.4g}] .. [{:.4g} "
        "{:.4g} {:.4g}] m by more than lost_margin = {:.3g} m (a damaged restart file, or one "
        "of another case)",
        p.id[i], i, p.position[i].x(), p.position[i].y(), p.position[i].z(), p.velocity[i].x(),
        p.velocity[i].y(), p.velocity[i].z(), domain_lo_.x(), domain_lo_.y(), domain_lo_.z(),
        domain_hi_.x(), domain_hi_.y(), domain_hi_.z(), lost_margin_);
  if (!p.position[i].allFinite() || !p.velocity[i].allFinite())
    return fmt::format(
        "particle {} has a non-finite position or velocity: the DEM step is unstable; lower "
        "time_step_fraction (now {:.3g}) or check the materials and the coupled loads",
        p.id[i], time_step_fraction_);
  const Eigen::Vector3d& x = p.position[i];
  const double out = std::max((domain_lo_ - x).maxCoeff(), (x - domain_hi_).maxCoeff());
  return fmt::format(
      "particle {} is lost: at ({:.4g}, {:.4g}, {:.4g}) m it lies {:.3g} m outside the "
      "domain [{:.4g} {:.4g} {:.4g}] .. [{:.4g} {:.4g} {:.4g}] m (walls, meshes and the "
      "particles at the start) by more than lost_margin = {:.3g} m; a wall or mesh lets "
      "particles through (an open face, an overlap too large for the time step) or the run is "
      "diverging; if the particle may go that far, raise the participant's key lost_margin",
      p.id[i], x.x(), x.y(), x.z(), out, domain_lo_.x(), domain_lo_.y(), domain_lo_.z(),
      domain_hi_.x(), domain_hi_.y(), domain_hi_.z(), lost_margin_);
}

}  // namespace partita::adapters
