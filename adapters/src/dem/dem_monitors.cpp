// The DEM adapter's monitor quantities (MonitorTable): each declared once, with its unit and doc
// (`partita docs dem`) and how the adapter gets it. Those that take a pass over every particle or
// pair (the kinetic energy, the mass, the contacts, the stable step) are computed only when a case
// records them. On several ranks (dem_ranks.cpp) the quantities a split sums over the ranks come
// from its last collective pass (OnRanks); the others are refused there.

#include <algorithm>

#include "dem_adapter.hpp"
#include "dem_ranks.hpp"

namespace partita::adapters {

namespace {

using Out = MonitorTable<DemAdapter>::Out;

}  // namespace

const MonitorTable<DemAdapter>& DemAdapter::monitor_table() {
  static const MonitorTable<DemAdapter> table = [] {
    using A = DemAdapter;
    // the DEM's energy accounting (dem::System::energies(), cumulative since the first step)
    // (on several ranks the split's books, summed over the ranks at the last monitors pass)
    const auto energies = [](const A& a) {
      return a.on_ranks() ? a.ranks_->books : a.system_.energy_tracking();
    };
    static constexpr auto books = [](const A& a) -> const dem::System::Energies& {
      return a.on_ranks() ? a.ranks_->energies : a.system_.energies();
    };
    const auto broken = [](const A& a) { return a.breakage() != nullptr; };
    // (on several ranks summed over the ranks at the last monitors pass)
    static constexpr auto breakage_counters = [](const A& a) -> const dem::BreakageCounters& {
      return a.on_ranks() ? a.ranks_->breakage : a.breakage()->counters();
    };
    MonitorTable<A> t;
    t.scalar("kinetic_energy", "J", "translational plus rotational kinetic energy of the particles",
             [](const A& a) {
               return a.on_ranks() ? a.ranks_->kinetic : a.system_.kinetic_energy();
             });
    t.scalar("particles", "", "number of particles", [](const A& a) {
      return a.on_ranks() ? a.ranks_->particles : static_cast<double>(a.system_.particle_count());
    });
    t.scalar("mass", "kg", "total mass of the particles", [](const A& a) {
      if (a.on_ranks()) return a.ranks_->mass;
      double mass = 0.0;
      for (const double m : a.system_.particles().mass) mass += m;
      return mass;
    });
    t.add(xyz_rows("momentum", "kg m/s",
                   "linear momentum sum m v of the particles, x (its change over an interval is "
                   "gravity's and the walls' and meshes' impulse on the particles: the weight "
                   "check of a bed that is not at rest)"),
          [](const A& a, const Out& out) {
            out({}, a.on_ranks() ? a.ranks_->momentum : a.system_.linear_momentum());
          });
    t.scalar("contacts_per_particle", "", "mean number of particle-particle contacts",
             [](const A& a) {
               return a.on_ranks() ? a.ranks_->contacts_per_particle
                                   : a.system_.mean_contacts_per_particle();
             });
    t.scalar("friction_work", "J",
             "(with energy_accounting: true, as the monitors down to energy_balance_error and "
             "<mesh>.work, <wall>.work) energy dissipated by Coulomb sliding in all contacts since "
             "the start (the capped tangential force's work on the relative motion plus the "
             "spring energy the cap released)",
             [](const A& a) { return books(a).friction; }, energies);
    t.scalar("damping_work", "J",
             "energy dissipated by viscous contact damping (normal, tangential), rolling "
             "resistance and yielding mesh contacts (breakage.below_limit: yield) since the start",
             [](const A& a) { return books(a).damping; }, energies);
    t.scalar("breakage_energy", "J",
             "mechanical energy (kinetic, potential, contact) before minus after the changes of "
             "the particle set (breakage) since the start",
             [](const A& a) { return books(a).breakage; }, energies);
    t.scalar("stiffening_work", "J",
             "energy the tangential springs lost without work (Mindlin's stiffness changing with "
             "the overlap, the history turned with the contact); negative: energy the law created",
             [](const A& a) { return books(a).stiffening; }, energies);
    t.scalar("gravity_work", "J", "work of gravity on the particles since the start",
             [](const A& a) { return books(a).gravity; }, energies);
    t.scalar("wall_work", "J", "work of all walls and meshes on the particles since the start",
             [](const A& a) {
               double walls_work = 0.0;
               for (const double w : books(a).wall_work) walls_work += w;
               for (const double w : books(a).mesh_work) walls_work += w;
               return walls_work;
             },
             energies);
    t.scalar("elastic_energy", "J", "elastic energy stored in the contacts (normal and tangential)",
             [](const A& a) {
               return a.on_ranks() ? a.ranks_->elastic : a.system_.elastic_energy();
             },
             [](const A& a) { return a.system_.energy_tracking() || a.on_ranks(); });
    t.scalar("energy_balance_error", "",
             "(wall_work + gravity_work - dKE - d elastic_energy - friction_work - damping_work - "
             "breakage_energy - stiffening_work) / (initial KE + initial elastic energy + the "
             "works' magnitudes); KE with velocity Verlet's half-step term",
             [](const A& a) {
               return a.on_ranks() ? a.ranks_->balance : a.system_.energy_balance_error();
             },
             energies);
    // meshes before walls: where a wall and a mesh share a name, the wall's value is the one a
    // monitor column takes (the last of that name)
    t.add(xyz_rows("<mesh>.force", "N", "total contact force of the particles on a mesh, x"),
          [](const A& a, const Out& out) {
            for (std::size_t k = 0; k < a.meshes_dem_.size(); ++k) {
              const auto& m = a.meshes_dem_[k];
              out({m.name}, a.on_ranks() ? a.ranks_->mesh_force[k] : a.system_.mesh_force(m.id));
            }
          });
    t.add({{"<mesh>.work", "J",
            "work of one mesh's motion on the particles since the start (a coupled FE surface: "
            "what the structure did on the granules)"}},
          [](const A& a, const Out& out) {
            const std::vector<double>& work = books(a).mesh_work;
            for (const auto& m : a.meshes_dem_) {
              const auto id = static_cast<std::size_t>(m.id);
              out({m.name}, {id < work.size() ? work[id] : 0.0});
            }
          },
          energies);
    t.add(xyz_rows("<wall>.force", "N",
                   "total contact force of the particles on a wall (a plane, or all faces of a "
                   "box), x"),
          [](const A& a, const Out& out) {
            for (std::size_t k = 0; k < a.walls_.size(); ++k)
              out({a.walls_[k].name},
                  a.on_ranks() ? a.ranks_->wall_force[k] : a.system_.wall_force(a.walls_[k].id));
          });
    t.add({{"<wall>.work", "J", "work of one wall's motion on the particles since the start"}},
          [](const A& a, const Out& out) {
            const std::vector<double>& work = books(a).wall_work;
            for (const auto& w : a.walls_) {
              const auto id = static_cast<std::size_t>(w.id);
              out({w.name}, {id < work.size() ? work[id] : 0.0});
            }
          },
          energies);
    t.add(xyz_rows("<wall>.<face>.force", "N",
                   "contact force of the particles on one closed face of a box wall (face: xmin, "
                   "xmax, ymin, ymax, zmin, zmax; e.g. walls.zmin.force_z, the floor's load); the "
                   "faces' forces add up to <wall>.force_*, x"),
          [](const A& a, const Out& out) {
            for (std::size_t k = 0; k < a.walls_.size(); ++k) {
              const auto& w = a.walls_[k];
              for (int face = 0; face < 6; ++face)  // a box wall's closed faces, each on its own
                if (w.faces & (1u << face))
                  out({w.name, kFaces[static_cast<std::size_t>(face)]},
                      a.on_ranks() ? a.ranks_->face_force[k][static_cast<std::size_t>(face)]
                                   : a.system_.wall_face_force(w.id, face).value_or(
                                         Eigen::Vector3d(0.0, 0.0, 0.0)));
            }
          });
    // monitor_particles: found by id (indices change when the particles are renumbered); a
    // particle that breakage removed keeps its last state; on ranks, the state the last
    // collective pass gathered
    std::vector<QuantityDoc> tracked = xyz_rows(
        "particle.<id>", "m",
        "position of the particle with that id (the ids listed in monitor_particles), x", ".");
    for (const auto& r : xyz_rows("particle.<id>.v", "m/s", "velocity of that particle, x", ""))
      tracked.push_back(r);
    t.add(tracked, [](const A& a, const Out& out) {
      const dem::Particles& p = a.system_.particles();
      for (std::size_t k = 0; k < a.tracked_.size(); ++k) {
        std::array<double, 6>& last = a.tracked_last_[k];
        if (a.on_ranks()) {  // (gathered from the owner by the last collective pass)
          out({std::to_string(a.tracked_[k])},
              {last[0], last[1], last[2], last[3], last[4], last[5]});
          continue;
        }
        std::size_t& i = a.tracked_index_[k];
        if (i >= p.size() || p.id[i] != a.tracked_[k])  // renumbered (or removed): find it again
          i = static_cast<std::size_t>(std::find(p.id.begin(), p.id.end(), a.tracked_[k]) -
                                       p.id.begin());
        if (i < p.size())
          for (int c = 0; c < 3; ++c) {
            last[static_cast<std::size_t>(c)] = p.position[i][c];
            last[static_cast<std::size_t>(c + 3)] = p.velocity[i][c];
          }
        out({std::to_string(a.tracked_[k])}, {last[0], last[1], last[2], last[3], last[4], last[5]});
      }
    });
    t.scalar("breakage.events", "", "particles broken so far (with breakage on)",
             [](const A& a) { return static_cast<double>(breakage_counters(a).events); }, broken);
    t.scalar("breakage.fragments", "", "fragments created so far",
             [](const A& a) { return static_cast<double>(breakage_counters(a).fragments); },
             broken);
    t.scalar("breakage.fragment_mass", "kg", "mass of the fragments created so far",
             [](const A& a) { return breakage_counters(a).fragment_mass; }, broken);
    t.scalar("breakage.mass_lost", "kg", "parent mass the inscribed fragments do not hold, lost",
             [](const A& a) { return breakage_counters(a).mass_lost; }, broken);
    t.scalar("breakage.mass_restored", "kg", "the same, given back to the fragments (mass option)",
             [](const A& a) { return breakage_counters(a).mass_restored; }, broken);
    t.scalar("breakage.energy_released", "J",
             "elastic contact energy released at breakage (with the powder's energy)",
             [](const A& a) { return breakage_counters(a).energy_released; }, broken);
    t.scalar("breakage.powder_events", "",
             "particles below the comminution limit crushed to powder (removed; below_limit: "
             "powder)",
             [](const A& a) { return static_cast<double>(breakage_counters(a).powder_events); },
             broken);
    t.scalar("breakage.powder_mass", "kg", "their mass, gone from the system",
             [](const A& a) { return breakage_counters(a).powder_mass; }, broken);
    t.scalar("breakage.powder_energy", "J",
             "their kinetic energy and contact (normal Hertz) energy when removed",
             [](const A& a) { return breakage_counters(a).powder_energy; }, broken);
    t.scalar("stable_time_step", "s", "the DEM's stable step now (falls as fragments appear)",
             [](const A& a) { return a.stable_time_step(); }, broken);
    return t;
  }();
  return table;
}

std::vector<MonitorValue> DemAdapter::monitors() const {
  return on_ranks() ? monitor_table().values(*this, {}) : monitor_values({});
}

std::vector<MonitorValue> DemAdapter::monitor_values(const std::vector<std::string>& names) const {
  // (on ranks, monitors() is what the run's set-up asks for the names and units, on every rank
  // alike: the values of the last collective pass, none at the start)
  if (on_ranks()) return lead_monitors(names);
  return monitor_table().values(*this, names);
}

}  // namespace partita::adapters
