#include "partita/adapters/register_all.hpp"

#ifdef PARTITA_HAVE_DEM
#include "dem/dem_adapter.hpp"
#endif
#ifdef PARTITA_HAVE_FEM
#include "fem/fem_adapter.hpp"
#endif
#ifdef PARTITA_HAVE_TUBE1D
#include "tube1d/tube_fluid_adapter.hpp"
#include "tube1d/tube_solid_adapter.hpp"
#endif

namespace partita::adapters {

void register_all(coupling::Registries& r) {
#ifdef PARTITA_HAVE_DEM
  r.solvers.add(
      "dem", "native DEM: Hertz-Mindlin spheres, walls, STL meshes as coupling interfaces",
      DemAdapter::create, DemAdapter::spec(),
      {{"kinetic_energy", "J", "translational plus rotational kinetic energy of the particles"},
       {"elastic_energy", "J", "elastic energy stored in the contacts (normal and tangential)"},
       {"friction_work", "J",
        "(with energy_accounting: true, as the monitors down to energy_balance_error) energy "
        "dissipated by Coulomb sliding in all contacts since the start (the capped "
        "tangential force's work on the relative motion plus the spring energy the cap released)"},
       {"damping_work", "J",
        "energy dissipated by viscous contact damping (normal, tangential) and rolling "
        "resistance since the start"},
       {"breakage_energy", "J",
        "mechanical energy (kinetic, potential, contact) before minus after the changes of the "
        "particle set (breakage) since the start"},
       {"stiffening_work", "J",
        "energy the tangential springs lost without work (Mindlin's stiffness changing with the "
        "overlap, the history turned with the contact); negative: energy the law created"},
       {"gravity_work", "J", "work of gravity on the particles since the start"},
       {"wall_work", "J", "work of all walls and meshes on the particles since the start"},
       {"<wall>.work", "J", "work of one wall's motion on the particles since the start"},
       {"<mesh>.work", "J",
        "work of one mesh's motion on the particles since the start (a coupled FE surface: what "
        "the structure did on the granules)"},
       {"energy_balance_error", "",
        "(wall_work + gravity_work - dKE - d elastic_energy - friction_work - damping_work - "
        "breakage_energy - stiffening_work) / (initial KE + initial elastic energy + the works' "
        "magnitudes); KE with velocity Verlet's half-step term"},
       {"particles", "", "number of particles"},
       {"mass", "kg", "total mass of the particles"},
       {"momentum_x", "kg m/s",
        "linear momentum sum m v of the particles, x (its change over an interval is gravity's "
        "and the walls' and meshes' impulse on the particles: the weight check of a bed that is "
        "not at rest)"},
       {"momentum_y", "kg m/s", "... y"},
       {"momentum_z", "kg m/s", "... z"},
       {"breakage.events", "", "particles broken so far (with breakage on)"},
       {"breakage.fragments", "", "fragments created so far"},
       {"breakage.fragment_mass", "kg", "mass of the fragments created so far"},
       {"breakage.mass_lost", "kg", "parent mass the inscribed fragments do not hold, lost"},
       {"breakage.mass_restored", "kg", "the same, given back to the fragments (mass option)"},
       {"breakage.energy_released", "J",
        "elastic contact energy released at breakage (with the powder's energy)"},
       {"breakage.powder_events", "",
        "particles below the comminution limit crushed to powder (removed; below_limit: powder)"},
       {"breakage.powder_mass", "kg", "their mass, gone from the system"},
       {"breakage.powder_energy", "J",
        "their kinetic energy and contact (normal Hertz) energy when removed"},
       {"stable_time_step", "s", "the DEM's stable step now (falls as fragments appear)"},
       {"contacts_per_particle", "", "mean number of particle-particle contacts"},
       {"<mesh>.force_x", "N", "total contact force of the particles on a mesh, x"},
       {"<mesh>.force_y", "N", "... y"},
       {"<mesh>.force_z", "N", "... z"},
       {"<wall>.force_x", "N",
        "total contact force of the particles on a wall (a plane, or all faces of a box), x"},
       {"<wall>.force_y", "N", "... y"},
       {"<wall>.force_z", "N", "... z"},
       {"<wall>.<face>.force_x", "N",
        "contact force of the particles on one closed face of a box wall (face: xmin, xmax, "
        "ymin, ymax, zmin, zmax; e.g. walls.zmin.force_z, the floor's load); the faces' forces "
        "add up to <wall>.force_*, x"},
       {"<wall>.<face>.force_y", "N", "... y"},
       {"<wall>.<face>.force_z", "N", "... z"},
       {"particle.<id>.x", "m",
        "position of the particle with that id (the ids listed in monitor_particles), x"},
       {"particle.<id>.y", "m", "... y"},
       {"particle.<id>.z", "m", "... z"},
       {"particle.<id>.vx", "m/s", "velocity of that particle, x"},
       {"particle.<id>.vy", "m/s", "... y"},
       {"particle.<id>.vz", "m/s", "... z"}});
#endif
#ifdef PARTITA_HAVE_FEM
  r.solvers.add(
      "fem",
      "native FEM: Hex8/Hex20/Tet4/Tet10; linear elastic, Neo-Hooke or J2 plasticity; static, "
      "Newmark or central-difference transient",
      FemAdapter::create, FemAdapter::spec(),
      {{"<interface>.force_x", "N",
        "total force the interface received (tractions times areas plus nodal forces), x"},
       {"<interface>.force_y", "N", "... y"},
       {"<interface>.force_z", "N", "... z"},
       {"<interface>.displacement_x", "m",
        "an interface: mean displacement of its nodes; a point (points:): the displacement "
        "interpolated at it, x"},
       {"<interface>.displacement_y", "m", "... y"},
       {"<interface>.displacement_z", "m", "... z"},
       {"static_reaction_x", "N",
        "minus the sum of the applied loads (gravity included): what the interfaces must "
        "carry in static equilibrium, x"},
       {"static_reaction_y", "N", "... y"},
       {"static_reaction_z", "N", "... z"},
       {"max_displacement", "m", "largest nodal displacement magnitude"},
       {"kinetic_energy", "J", "1/2 v^T M v"},
       {"strain_energy", "J", "stored elastic energy (1/2 u^T K u when linear)"},
       {"plastic_work", "J", "work dissipated by plastic flow"},
       {"external_work", "J", "work of the applied and coupled loads"},
       {"damping_work", "J", "work dissipated by Rayleigh damping"},
       {"energy_balance", "J",
        "external work - (strain + kinetic + plastic + damping + eroded + enhanced strain): "
        "zero for an exact balance"},
       {"newton_iterations", "",
        "Newton iterations of the last step (nonlinear materials; 0 on the linear path)"},
       {"failed_elements", "", "elements whose mean equivalent plastic strain reached eps_f"},
       {"first_failure_time", "s", "when the first element failed (-1 until then)"},
       {"eroded_energy", "J",
        "strain energy, plastic work and kinetic energy that left with eroded elements"},
       {"enhanced_strain_work", "J",
        "dissipated by the reduced Hex8's once-a-step update of its enhanced thickness strain "
        "(0 without hex8: reduced)"},
       {"max_equivalent_plastic_strain", "", "largest over the quadrature points"},
       {"<point>.equivalent_plastic_strain", "",
        "a point (points:), nonlinear material: the mean of its element's points"},
       {"<region>.plastic_work", "J", "with two or more element regions (parts): per region"},
       {"<region>.strain_energy", "J", "... stored elastic energy"},
       {"<region>.kinetic_energy", "J", "... 1/2 v_e^T M_e v_e"}});
#endif
#ifdef PARTITA_HAVE_TUBE1D
  r.solvers.add("tube1d-fluid",
                "1D elastic tube: quasi-1D incompressible flow (writes pressure, reads area)",
                TubeFluidAdapter::create, TubeFluidAdapter::spec(),
                {{"inlet_pressure", "Pa", "pressure in the first cell"},
                 {"outlet_pressure", "Pa", "pressure in the last cell"},
                 {"inlet_velocity", "m/s", "velocity in the first cell"}});
  r.solvers.add("tube1d-solid",
                "1D elastic tube: tube law a(p) (reads pressure, writes cross_section_area)",
                TubeSolidAdapter::create, TubeSolidAdapter::spec(),
                {{"mid_area", "m^2", "cross-section area at the middle of the tube"},
                 {"max_area", "m^2", "largest cross-section area"}});
#endif
  (void)r;
}

}  // namespace partita::adapters
