// The FEM adapter's monitor quantities (MonitorTable): each declared once, with its unit and doc
// (`partita docs fem`) and how the adapter gets it. The energies (a sparse product over the whole
// mesh each) are computed only when a case records them.

#include "fem_adapter.hpp"

namespace partita::adapters {

namespace {

using Out = MonitorTable<FemAdapter>::Out;

}  // namespace

const MonitorTable<FemAdapter>& FemAdapter::monitor_table() {
  static const MonitorTable<FemAdapter> table = [] {
    using A = FemAdapter;
    MonitorTable<A> t;
    t.add(xyz_rows("<interface>.force", "N",
                   "total force the interface received (tractions times areas plus nodal "
                   "forces), x"),
          [](const A& a, const Out& out) {
            for (const auto& i : a.interfaces_) {
              // sum_q t_q w_q (tractions) + sum_a f_a (nodal forces)
              Eigen::Vector3d f = Eigen::Vector3d::Zero();
              if (i.has_tractions)
                for (Eigen::Index q = 0; q < i.tractions.rows(); ++q)
                  f += i.tractions.row(q).transpose() * i.qp_weights[static_cast<std::size_t>(q)];
              if (i.has_forces) f += i.nodal_forces.colwise().sum().transpose();
              out({i.name}, f);
            }
          });
    t.add(xyz_rows("<interface>.displacement", "m",
                   "an interface: mean displacement of its nodes; a point (points:): the "
                   "displacement interpolated at it, x"),
          [](const A& a, const Out& out) {
            const Eigen::VectorXd& u = a.solver_->displacement();
            for (const auto& i : a.interfaces_) {
              Eigen::Vector3d d = Eigen::Vector3d::Zero();
              for (const std::size_t n : i.nodes) d += u.segment<3>(3 * static_cast<Eigen::Index>(n));
              if (!i.nodes.empty()) d /= static_cast<double>(i.nodes.size());
              out({i.name}, d);
            }
            for (const auto& p : a.points_) out({p.name}, a.locator_->interpolate(p.at, u));
          });
    t.add({{"<point>.equivalent_plastic_strain", "",
            "a point (points:), nonlinear material: the mean of its element's points"}},
          [](const A& a, const Out& out) {
            if (a.points_.empty()) return;
            const Eigen::VectorXd eqps = a.solver_->element_equivalent_plastic_strain();
            if (eqps.size() == 0) return;  // a linear material
            for (const auto& p : a.points_)
              out({p.name}, {eqps[static_cast<Eigen::Index>(p.at.element)]});
          });
    t.add(xyz_rows("static_reaction", "N",
                   "minus the sum of the applied loads (gravity included): what the interfaces "
                   "must carry in static equilibrium, x"),
          [](const A& a, const Out& out) {
            const Eigen::Vector3d applied =
                a.solver_->total_external_force() - a.solver_->total_coupling_force();
            out({}, -applied);
          });
    t.scalar("max_displacement", "m", "largest nodal displacement magnitude",
             [](const A& a) { return a.solver_->max_displacement(); });
    t.scalar("min_element_step", "s",
             "the smallest stable step of the elements not eroded at their present shape: each "
             "element's bound at rest times its length V / A_max now over the one at rest (an "
             "explicit step above it integrates that element unstably; 0: an element turned "
             "inside out)",
             [](const A& a) { return a.solver_->min_element_time_step(); });
    t.scalar("kinetic_energy", "J", "1/2 v^T M v",
             [](const A& a) { return a.solver_->kinetic_energy(); });
    t.scalar("strain_energy", "J", "stored elastic energy (1/2 u^T K u when linear)",
             [](const A& a) { return a.solver_->strain_energy(); });
    t.scalar("plastic_work", "J", "work dissipated by plastic flow",
             [](const A& a) { return a.solver_->plastic_work(); });
    t.scalar("external_work", "J", "work of the applied and coupled loads",
             [](const A& a) { return a.solver_->external_work(); });
    t.scalar("damping_work", "J", "work dissipated by Rayleigh damping",
             [](const A& a) { return a.solver_->damping_work(); });
    const auto mass_scaled = [](const A& a) {
      return a.solver_->options().mass_scaling_time_step > 0.0;
    };
    t.scalar("added_mass", "kg",
             "mass that mass scaling added (with analysis.mass_scaling_time_step)",
             [](const A& a) { return a.solver_->added_mass(); }, mass_scaled);
    t.scalar("added_mass_percent", "%", "the same in percent of the model's physical mass",
             [](const A& a) {
               const double added = a.solver_->added_mass(), mass = a.solver_->physical_mass();
               return mass > 0.0 ? 100.0 * added / mass : 0.0;
             },
             mass_scaled);
    const auto self_contact = [](const A& a) { return a.self_contact_ != nullptr; };
    t.scalar("self_contact_nodes", "",
             "nodes in contact with a face of the body itself (self_contact:)",
             [](const A& a) { return static_cast<double>(a.self_contact_->active_nodes()); },
             self_contact);
    t.scalar("self_contact_force", "N", "the sum of the self contact's normal forces |p| on its nodes",
             [](const A& a) { return a.self_contact_->total_normal_force(); }, self_contact);
    t.scalar("self_contact_energy", "J",
             "the self contact's penalty energy, 1/2 k (depth - pre-penetration)^2 over its nodes (part of strain_energy)",
             [](const A& a) { return a.self_contact_->stored_energy(); }, self_contact);
    // rigid indenters (indenters:, indenter_config.hpp); before the regions' quantities: where a
    // region and an indenter share a name, the region's kinetic_energy is the one a monitor
    // column takes (the last of that name)
    t.add(xyz_rows("<indenter>", "m",
                   "a rigid indenter (indenters:): its reference point, `position` plus its "
                   "displacement, x",
                   "."),
          [](const A& a, const Out& out) {
            for (const auto& ind : a.indenters_)
              out({ind.name}, ind.reference + ind.contact->indenter().displacement());
          });
    t.add(xyz_rows("<indenter>.v", "m/s", "velocity of an indenter, x", ""),
          [](const A& a, const Out& out) {
            for (const auto& ind : a.indenters_) out({ind.name}, ind.contact->indenter().velocity());
          });
    t.add(xyz_rows("<indenter>.force", "N", "the contact force of the structure on an indenter, x"),
          [](const A& a, const Out& out) {
            for (const auto& ind : a.indenters_) out({ind.name}, ind.contact->contact_force());
          });
    t.add({{"<indenter>.penetration", "m",
            "an indenter's displacement along its path since its first contact (0 before)"}},
          [](const A& a, const Out& out) {
            for (const auto& ind : a.indenters_)
              out({ind.name}, {ind.contact->indenter().penetration()});
          });
    t.add({{"<indenter>.work", "J", "work an indenter did on the structure since the start"}},
          [](const A& a, const Out& out) {
            for (const auto& ind : a.indenters_) out({ind.name}, {ind.contact->indenter().work()});
          });
    t.add(xyz_rows("<indenter>.external_force", "N",
                   "a free indenter (motion.mass): the force the coupling hands over on its "
                   "surface, x"),
          [](const A& a, const Out& out) {
            for (const auto& ind : a.indenters_)
              if (ind.contact->indenter().is_free())
                out({ind.name}, ind.contact->indenter().external_force());
          });
    t.add({{"<indenter>.external_work", "J",
            "a free indenter: the work of the forces handed over on it since the start"}},
          [](const A& a, const Out& out) {
            for (const auto& ind : a.indenters_)
              if (ind.contact->indenter().is_free())
                out({ind.name}, {ind.contact->indenter().external_work()});
          });
    t.add({{"<indenter>.kinetic_energy", "J", "an indenter's kinetic energy (0 when driven)"}},
          [](const A& a, const Out& out) {
            for (const auto& ind : a.indenters_)
              out({ind.name}, {ind.contact->indenter().kinetic_energy()});
          });
    t.add({{"<indenter>.contact_energy", "J", "energy stored in an indenter's penalty springs"}},
          [](const A& a, const Out& out) {
            for (const auto& ind : a.indenters_) out({ind.name}, {ind.contact->stored_energy()});
          });
    t.add({{"<indenter>.friction_work", "J",
            "work dissipated by an indenter's friction since the start"}},
          [](const A& a, const Out& out) {
            for (const auto& ind : a.indenters_) out({ind.name}, {ind.contact->dissipated_work()});
          });
    t.add({{"<indenter>.contact_nodes", "", "nodes in contact with an indenter"}},
          [](const A& a, const Out& out) {
            for (const auto& ind : a.indenters_)
              out({ind.name}, {static_cast<double>(ind.contact->active_nodes())});
          });
    t.scalar("energy_balance", "J",
             "external work + the indenters' work - (strain + kinetic + plastic + damping + "
             "eroded + enhanced strain): zero for an exact balance",
             [](const A& a) {
               double indenter_work = 0.0;
               for (const auto& ind : a.indenters_) indenter_work += ind.contact->indenter().work();
               return a.solver_->energy_balance() + indenter_work;
             });
    // rupture and energies by part (fem_rupture.hpp)
    t.scalar("failed_elements", "",
             "elements whose mean equivalent plastic strain reached eps_f (rtcl, bwh: whose "
             "points' mean damage reached 1)",
             [](const A& a) { return static_cast<double>(a.solver_->failed_elements()); });
    // -1 until an element fails (a monitor value must be finite: the core takes a non-finite one
    // for a diverging run)
    t.scalar("first_failure_time", "s", "when the first element failed (-1 until then)",
             [](const A& a) {
               const auto first = a.solver_->first_failure();
               return first ? first->time : -1.0;
             });
    t.scalar("eroded_energy", "J",
             "strain energy, plastic work and kinetic energy that left with eroded elements",
             [](const A& a) { return a.solver_->eroded_energy(); });
    t.scalar("enhanced_strain_work", "J",
             "dissipated by the reduced Hex8's once-a-step update of its enhanced thickness strain "
             "(0 without hex8: reduced)",
             [](const A& a) { return a.solver_->enhanced_strain_work(); });
    t.scalar("max_equivalent_plastic_strain", "", "largest over the quadrature points",
             [](const A& a) { return a.solver_->max_equivalent_plastic_strain(); });
    t.add({{"<region>.plastic_work", "J", "with two or more element regions (parts): per region"},
           {"<region>.strain_energy", "J", "... stored elastic energy"},
           {"<region>.kinetic_energy", "J", "... 1/2 v_e^T M_e v_e"}},
          [](const A& a, const Out& out) {
            const auto& regions = a.solver_->mesh().region_names();
            const fem::RegionEnergies e = a.solver_->region_energies();  // one pass
            for (std::size_t i = 0; i < regions.size(); ++i)
              out({regions[i]}, {e.plastic_work[i], e.strain_energy[i], e.kinetic_energy[i]});
          },
          [](const A& a) { return a.solver_->mesh().region_names().size() >= 2; });
    t.add({{"<region>.failed_elements", "",
            "with two or more element regions (parts) and a failure criterion: failed elements "
            "per region"},
           {"<region>.first_failure_time", "s",
            "... when the region's first element failed (-1 until then)"}},
          [](const A& a, const Out& out) {
            const fem::StructuralSolver& s = *a.solver_;
            const auto& regions = s.mesh().region_names();
            std::vector<double> count(regions.size(), 0.0), first(regions.size(), -1.0);
            for (std::size_t e = 0; e < s.mesh().num_elements(); ++e) {
              const double failed_at = s.element_failure_time(e);
              if (failed_at < 0.0) continue;
              const auto r = static_cast<std::size_t>(s.mesh().elements()[e].region);
              count[r] += 1.0;
              if (first[r] < 0.0 || failed_at < first[r]) first[r] = failed_at;
            }
            for (std::size_t i = 0; i < regions.size(); ++i) out({regions[i]}, {count[i], first[i]});
          },
          [](const A& a) { return a.solver_->mesh().region_names().size() >= 2; });
    t.scalar("newton_iterations", "",
             "Newton iterations of the last step (nonlinear materials; 0 on the linear path)",
             [](const A& a) { return static_cast<double>(a.solver_->newton_iterations()); });
    return t;
  }();
  return table;
}

std::vector<MonitorValue> FemAdapter::monitors() const { return monitor_values({}); }

std::vector<MonitorValue> FemAdapter::monitor_values(const std::vector<std::string>& names) const {
  return monitor_table().values(*this, names);
}

}  // namespace partita::adapters
