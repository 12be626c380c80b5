#pragma once
// Crushable particles (seed 001, eq. 2): a step hook that replaces a particle loaded beyond its
// strength by fragments inscribed in it, at the end of the step.
//
// Criterion (Russell & Muir Wood 2009; Ciantia et al. 2015; seed 001 eq. 2): the Hertzian contact
// of normal force F, effective modulus E' (1/E' = (1-nu1^2)/E1 + (1-nu2^2)/E2) and radius r'
// (1/r' = 1/r1 + 1/r2; a plane or mesh: r' = r) has the radius a = (3 F r'/(4 E'))^(1/3); the
// particle breaks when the mean pressure F/(pi a^2) reaches its strength sigma, i.e. when
//   F >= [sigma pi (3 r'/(4 E'))^(2/3)]^3 = (9/16) pi^3 sigma^3 (r'/E')^2,
// checked for every contact of the particle (particle-particle, particle-plane, particle-mesh) as
//   F (E'/r')^2 >= (9/16) pi^3 sigma^3
// (the force pass records the left side's largest value per particle: System::contact_load()).
// Strength with the Weibull size effect: sigma = s sigma_lim,0 (d/d0)^(-3/m), s = 1 without
// scatter, else s = (-ln U)^(1/m), U uniform in (0, 1] drawn from (seed, particle id): a Weibull
// law of modulus m with survival exp(-(sigma/sigma_c)^m). A particle's strength is drawn once,
// when the hook first sees it (fragments: at birth), and kept in the store array
// "breakage_strength", so it follows the particle and is saved and restored with it. The load at
// which it breaks is kept beside it ("breakage_load_limit"): the force pass compares each load
// with it as the load is completed (System::contact_load_reached()), so a step in which nothing
// breaks costs no pass over the particles here (the aim: at most 5 % on a large bed).
// Particles with d < d_min (comminution limit) do not fragment; fragments are breakable. With
// BreakageParameters::powder a particle below d_min whose load reaches its strength (the same
// criterion) is crushed to powder: removed at the end of the step, its mass, kinetic energy and
// contact energy counted (the System books the change of mechanical energy as breakage energy,
// as for fragments). Without it such a particle never breaks.
//
// Fragments (FragmentPattern, in a random orientation drawn from (seed, id)): radius R rho_k at
// x + R Q c_k, material of the parent, velocity v + omega x (R Q c_k) and spin omega (the parent's
// rigid motion). Radii are reduced by 1e-9 relative so that fragments do not touch each other and
// overlap every neighbour strictly less than the parent did. Mass: without restoration each
// fragment has its material's density and the rest of the parent's mass is lost (it carries the
// momentum m_lost v and the angular momentum (I_p - I_fragments) omega away: counted); with
// restoration the fragments' masses are scaled by M/M_fragments and each fragment's moment of
// inertia is raised by an equal share of the parent's I_p = 2/5 M R^2 minus the set's inertia
// about the parent's centre, so linear and angular momentum and kinetic energy are those of the
// parent. Particles broken in one step are handled in ascending index; the set changes at the end
// of the step through System::replace_particles() (by default the next step searches the lists again
// and the new fragments' contacts act from its force pass; with local fragment insertion the
// fragments join their parent's neighbours in the lists at once). Smaller fragments lower the Rayleigh step: read System::rayleigh_time_step() again.

#include "partita/dem/breakage_counters.hpp"
#include "partita/dem/breakage_parameters.hpp"
#include "partita/dem/fragment_pattern.hpp"
#include "partita/dem/step_hook.hpp"
#include "partita/dem/system.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace partita::dem {

class Breakage final : public StepHook {
 public:
  /// Throws Error on parameters out of range (m, d0, sigma_lim,0, d_min > 0 and finite).
  explicit Breakage(const BreakageParameters& parameters);

  std::string name() const override { return "breakage"; }
  std::unique_ptr<StepHook> clone() const override { return std::make_unique<Breakage>(*this); }
  void attach(System& system) override;
  bool wants_contact_load() const override { return true; }
  int contact_load_limit() const override { return h_limit_; }
  ContactYield contact_yield() const override {
    return parameters_.yield ? ContactYield{h_strength_, parameters_.comminution_limit} : ContactYield{};
  }
  void end_of_step(System& system, double dt) override;
  void write_state(BinaryWriter& out) const override;
  void read_state(BinaryReader& in) override;
  /// The load limits again from the strengths drawn (the state's limits may follow another
  /// version's rule for the particles below the comminution limit).
  void restored(System& system) override;

  // on a split bed (StepHook's protocol): the particles a subdomain owns break there, their
  // fragments numbered by the stepper; the fragments' contact energy (energy_released) is taken
  // in settled(), where each fragment is owned once the ghosts hold those born elsewhere
  bool replaces_particles() const override { return true; }
  int successors() const override { return pattern_.size(); }
  void choose(System& system, const std::vector<char>& skip, std::vector<std::size_t>& replaced,
              std::vector<std::size_t>& removed) override;
  void replace(System& system, const std::vector<std::size_t>& replaced,
               const std::vector<std::size_t>& removed,
               const std::vector<std::int64_t>& first_id) override;
  void settled(System& system, const std::vector<char>& skip, std::int64_t first_id,
               std::int64_t end_id) override;
  /// The counters' totals (besides smallest_fragment) as exact sums, in the order of
  /// counters_from(); kept beside counters() by every change, saved only in a split bed's restart.
  std::vector<ExactSum> sums() const override { return sums_; }
  void set_sums(const std::vector<ExactSum>& sums) override;
  /// Counters from sums()' totals (events, fragments, fragment_mass, mass_lost, mass_restored,
  /// energy_released, powder_events, powder_mass, powder_energy); smallest_fragment 0.
  static BreakageCounters counters_from(const std::vector<double>& totals);
  static constexpr std::size_t sum_count = 9;

  const BreakageParameters& parameters() const { return parameters_; }
  const FragmentPattern& pattern() const { return pattern_; }
  const BreakageCounters& counters() const { return counters_; }

  /// Characteristic strength sigma_lim,0 (d/d0)^(-3/m) of a particle of diameter d [Pa].
  double characteristic_strength(double diameter) const;
  /// The strength drawn for the particle with this id and diameter (scatter as declared).
  double draw_strength(std::int64_t id, double diameter) const;
  /// The force at which a particle of strength sigma breaks in a contact of E', r' (eq. 2) [N].
  static double critical_force(double strength, double e_eff, double r_eff);
  /// Replaces the particles of the given indices (ascending, each < particle_count()) by their
  /// fragments now, whatever their load and size.
  void break_particles(System& system, const std::vector<std::size_t>& indices);
  /// Breaks `fragment` (as break_particles()) and removes `powder` as powder (counted), in one
  /// change of the particle set; both ascending, disjoint, each < particle_count().
  void crush(System& system, const std::vector<std::size_t>& fragment,
             const std::vector<std::size_t>& powder);

 private:
  // elastic (normal Hertz) energy of particle i's contacts at the current positions: with the
  // system's lists current, from its listed neighbours [first, last) (ascending) and its mesh
  // candidates; otherwise by looking at every particle and triangle (the same value: the same
  // contacts in the same order)
  double contact_energy(const System& system, std::size_t i, const int* first,
                        const int* last) const;
  double contact_energy(const System& system, std::size_t i) const;
  // the sum of contact_energy() over `which`, from the listed neighbours when the lists are
  // current
  double contact_energies(const System& system, const std::vector<std::size_t>& which);

  // crush() with the fragments' ids (first_id[k]: parent k's first; null: the next free ids);
  // with ids the fragments' contact energy waits for settled()
  void crush(System& system, const std::vector<std::size_t>& fragment,
             const std::vector<std::size_t>& powder, const std::vector<std::int64_t>* first_id);
  void count(std::size_t which, double value) {
    sums_[which].add(value);
  }
  std::vector<ExactSum> sums_ = std::vector<ExactSum>(sum_count);
  BreakageParameters parameters_;
  FragmentPattern pattern_;
  BreakageCounters counters_;
  // load limit (9/16) pi^3 sigma^3 per particle (infinite below d_min; -1: strength not drawn
  // yet): the force pass compares each load with it, end_of_step() looks at the particles only
  // when one reached it
  void set_limit(System& system, std::size_t i, double strength) const;
  int h_strength_ = -1;
  int h_limit_ = -1;
  std::vector<std::size_t> broken_;  // scratch (reserved: no allocation while nothing breaks)
  std::vector<std::size_t> powder_;  // (the same, for the particles crushed to powder)
  std::vector<std::size_t> parents_, added_;            // scratch of crush()
  std::vector<System::Fragment> fragments_;             // (the same)
  std::vector<int> nb_offsets_, nb_items_;              // (the same: listed neighbours)
  mutable std::vector<double> mesh_overlap_;  // (contact_energy(): per mesh, from outside)
  mutable std::vector<double> mesh_inside_;   // (per one-sided mesh: the way out from inside)
};

}  // namespace partita::dem
