// Building a DEM adapter from its validated case section: materials and their interactions, the
// particles (generated to a porosity or read from a LAMMPS data file), walls, the meshes that
// are coupling interfaces, breakage, the tracked particles, and the checks of the set-up (every
// pair that can touch has an interaction; no particle absurdly far from the geometry).

#include <fmt/format.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <numbers>

#include "dem_adapter.hpp"
#include "dem_ranks.hpp"
#include "partita/dem/breakage.hpp"
#include "partita/dem/error.hpp"
#include "partita/dem/lammps_data.hpp"
#include "partita/dem/wall_servo.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"
#include "partita/interface/stl.hpp"
#include "partita/interface/time_table.hpp"

namespace partita::adapters {

namespace {

using config::Node;

// A generated rectangle of cells[0] x cells[1] cells, two triangles each (mesh: {rectangle: ...}).
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
        auto servo = std::make_unique<dem::WallServo>(sp);  // (checks the parameters)
        // on several ranks each System holds a part of the wall's force: the adapter applies the
        // servo's law with the force summed over the ranks (dem_ranks.cpp)
        if (context.ranks)
          wall.servo = sp;
        else
          system_.add_hook(std::move(servo));
      }
      walls_.push_back(wall);
    }

    // Meshes: the coupling interfaces.
    for (const Node& m : c["meshes"].items()) {
      CouplingMesh cm;
      cm.name = m.string("name");
      const bool one_sided = m.has("one_sided") && m.boolean("one_sided");
      for (const auto& other : meshes_dem_)
        if (other.name == cm.name) m["name"].fail("mesh name '" + cm.name + "' is used twice");
      Mesh mesh;
      if (m.has("from")) {  // built when the core hands the surface over (receive_mesh)
        for (const auto& r : requests_)
          if (r.name == cm.name) m["name"].fail("mesh name '" + cm.name + "' is used twice");
        requests_.push_back(MeshRequest{cm.name, m.string("from"), m["from"]});
        request_materials_.push_back(material_id(m["material"]));
        request_one_sided_.push_back(one_sided ? 1 : 0);
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
      add_coupling_mesh(cm.name, mesh, material_id(m["material"]), one_sided);
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
  // mpirun -n N partita run CASE: the bed split over the participant's ranks (dem_ranks.cpp)
  if (context.ranks) setup_ranks(context);
}

void DemAdapter::add_breakage(const config::Node& b) {
  dem::BreakageParameters p;
  p.limit_strength = b.real("limit_strength");
  p.reference_size = b.real("reference_size");
  p.weibull_modulus = b.real("weibull_modulus");
  p.scatter = b.string("scatter") == "weibull";
  p.comminution_limit = b.real("comminution_limit");
  p.powder = b.string("below_limit") == "powder";
  p.yield = b.string("below_limit") == "yield";
  p.pattern = dem::FragmentPattern::named(b.string("pattern")).kind();
  p.restore_mass = b.string("mass") == "restored";
  p.seed = static_cast<std::uint64_t>(b.integer("seed"));
  breakage_ = system_.add_hook(std::make_unique<dem::Breakage>(p));
  system_.set_local_fragment_insertion(b.string("lists") == "local");
  double d_max = 0.0;
  for (double r : system_.particles().radius) d_max = std::max(d_max, 2.0 * r);
  if (p.comminution_limit > d_max)
    log::get("adapters")
        ->warn(
            "dem '{}': breakage.comminution_limit {:.4g} m is above the largest particle "
            "diameter {:.4g} m: nothing can break",
            name_, p.comminution_limit, d_max);
}

}  // namespace partita::adapters
