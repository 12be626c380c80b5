#include "partita/dem/breakage.hpp"

#include "partita/dem/error.hpp"
#include "partita/dem/system.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

#include <Eigen/Geometry>

namespace partita::dem {

namespace {

constexpr double shrink = 1.0 - 1e-9;  // fragments strictly inside the parent

std::uint64_t mix(std::uint64_t z) {  // SplitMix64 finaliser
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// Uniform in (0, 1], stream k of particle `id` under `seed` (counter-based: no state to carry).
double uniform(std::uint64_t seed, std::int64_t id, std::uint64_t k) {
  const std::uint64_t z = mix(seed ^ mix(static_cast<std::uint64_t>(id) ^ mix(k)));
  return (static_cast<double>(z >> 11) + 1.0) * 0x1.0p-53;
}

void check_positive(double value, const char* what, std::ostringstream& msg) {
  if (msg.str().empty() && !(value > 0.0 && std::isfinite(value)))
    msg << "breakage: " << what << " must be finite and > 0, got " << value;
}

}  // namespace

Breakage::Breakage(const BreakageParameters& p) : parameters_(p), pattern_(p.pattern) {
  std::ostringstream msg;
  check_positive(p.limit_strength, "the limit strength sigma_lim,0 [Pa]", msg);
  check_positive(p.reference_size, "the reference size d0 [m]", msg);
  check_positive(p.weibull_modulus, "the Weibull modulus m", msg);
  check_positive(p.comminution_limit, "the comminution limit d_min [m]", msg);
  if (p.powder && p.yield)
    msg << "below the comminution limit a particle is either crushed to powder or yields, not "
           "both; ";
  if (!msg.str().empty()) throw Error(msg.str());
  broken_.reserve(64);
  powder_.reserve(64);
}

void Breakage::attach(System& system) {
  ParticleStore& store = system.store_unsynced();
  if (store.find("breakage_strength") >= 0)
    throw Error("add_hook: a breakage model is attached already (one per system)");
  h_strength_ = store.add_array<double>("breakage_strength", 1, -1.0);  // -1: not drawn yet
  // -1: below any load (>= 0), so a new particle makes the next force pass report a reached
  // limit and end_of_step() draws its strength
  h_limit_ = store.add_array<double>("breakage_load_limit", 1, -1.0);
}

void Breakage::set_limit(System& system, std::size_t i, double strength) const {
  ParticleStore& store = system.store_unsynced();
  const double pi3 = std::numbers::pi * std::numbers::pi * std::numbers::pi;
  const double limit = 9.0 / 16.0 * pi3 * strength * strength * strength;
  // below the limit, yielding: a yielding contact holds its mean pressure at the strength (its
  // load at the limit); one pressed to 1.5 times that (a mesh contact flattened to the centre and
  // pressed on elastically, a plane, a hard impact) crushes the particle to powder
  constexpr double squeezed = 1.5 * 1.5 * 1.5;
  store.array<double>(h_limit_)[i] =
      parameters_.powder || 2.0 * store.core().radius[i] >= parameters_.comminution_limit
          ? limit
          : parameters_.yield ? squeezed * limit : std::numeric_limits<double>::infinity();
}

double Breakage::characteristic_strength(double diameter) const {
  // sigma_lim = sigma_lim,0 (d/d0)^(-3/m)
  return parameters_.limit_strength *
         std::pow(diameter / parameters_.reference_size, -3.0 / parameters_.weibull_modulus);
}

double Breakage::draw_strength(std::int64_t id, double diameter) const {
  const double sigma_c = characteristic_strength(diameter);
  if (!parameters_.scatter) return sigma_c;
  // Weibull, survival P(sigma) = exp(-(sigma/sigma_c)^m): sigma = sigma_c (-ln U)^(1/m)
  const double u = uniform(parameters_.seed, id, 0);
  return sigma_c * std::pow(-std::log(u), 1.0 / parameters_.weibull_modulus);
}

double Breakage::critical_force(double strength, double e_eff, double r_eff) {
  // F = [sigma pi (3 r'/(4 E'))^(2/3)]^3 = (9/16) pi^3 sigma^3 (r'/E')^2
  const double pi3 = std::numbers::pi * std::numbers::pi * std::numbers::pi;
  const double ratio = r_eff / e_eff;
  return 9.0 / 16.0 * pi3 * strength * strength * strength * ratio * ratio;
}

void Breakage::end_of_step(System& system, double /*dt*/) {
  ParticleStore& store = system.store_unsynced();
  const Particles& p = store.core();
  std::vector<double>& strength = store.array<double>(h_strength_);
  const std::vector<double>& load = system.contact_load();
  const std::size_t n = p.size();
  if (load.size() != n) return;  // no force pass since the set changed
  if (!system.contact_load_reached()) return;  // (every load below its limit)
  // break when F (E'/r')^2 >= (9/16) pi^3 sigma^3 (eq. 2, see the class comment): into
  // fragments for d >= d_min, to powder below it (the limit is infinite there when the particle
  // is unbreakable, 1.5^3 times eq. 2's when it yields: set_limit())
  const std::vector<double>& limit = store.array<double>(h_limit_);
  broken_.clear();
  powder_.clear();
  for (std::size_t i = 0; i < n; ++i) {
    if (strength[i] < 0.0) {
      strength[i] = draw_strength(p.id[i], 2.0 * p.radius[i]);
      set_limit(system, i, strength[i]);
    }
    if (load[i] >= limit[i])
      (2.0 * p.radius[i] >= parameters_.comminution_limit ? broken_ : powder_).push_back(i);
  }
  if (!broken_.empty() || !powder_.empty()) crush(system, broken_, powder_);
}

namespace {

// Hertz: 8/15 E* sqrt(R*) delta^(5/2)
double hertz(double e_star, double r_eff, double delta) {
  return 8.0 / 15.0 * e_star * std::sqrt(r_eff) * std::pow(delta, 2.5);
}

}  // namespace

double Breakage::contact_energy(const System& system, std::size_t i, const int* first,
                                const int* last) const {
  const Particles& p = system.particles();
  const ContactModel& model = system.contact_model();
  const Eigen::Vector3d& x = p.position[i];
  const double r = p.radius[i];
  double e = 0.0;
  auto pair = [&](std::size_t j) {
    const double delta = r + p.radius[j] - (x - p.position[j]).norm();
    if (delta > 0.0)
      e += hertz(model.pair(p.material[i], p.material[j]).e_star,
                 r * p.radius[j] / (r + p.radius[j]), delta);
  };
  const bool listed = first != nullptr;
  if (listed) {
    for (const int* j = first; j != last; ++j) pair(static_cast<std::size_t>(*j));
  } else {
    for (std::size_t j = 0; j < p.size(); ++j)
      if (j != i) pair(j);
  }
  for (const PlaneWall& w : system.planes()) {
    const double delta = r - (x - w.point).dot(w.normal);
    if (delta > 0.0) e += hertz(model.pair(p.material[i], w.material).e_star, r, delta);
  }
  // the deepest overlap with an active triangle of each mesh (listed: among the particle's
  // candidates, which hold every triangle it can touch; a triangle taken out of the contacts
  // touches nothing); two-sided: the nearest triangle's. One-sided (MeshContacts::evaluate()):
  // a centre in front of any triangle within reach is outside the body (the deepest of those);
  // a centre behind every one inside it (the shallowest face: the way out).
  constexpr double none = -std::numeric_limits<double>::max();
  mesh_overlap_.assign(system.mesh_count(), none);
  mesh_inside_.assign(system.mesh_count(), std::numeric_limits<double>::max());
  const auto deepest = [&](int m, int t) {
    const TriangleMesh& mesh = system.mesh(m);
    if (!mesh.triangle_active(t)) return;
    bool behind = false;
    const double delta = mesh.overlap(t, x, r, &behind);
    if (behind)
      mesh_inside_[m] = std::min(mesh_inside_[m], delta);
    else if (delta > 0.0 || !mesh.one_sided())
      mesh_overlap_[m] = std::max(mesh_overlap_[m], delta);
  };
  if (listed) {
    const NeighborList& nl = system.neighbor_list();
    for (const MeshCandidate* c = nl.mesh_candidates_begin(i); c != nl.mesh_candidates_end(i); ++c)
      deepest(c->mesh, c->triangle);
  } else {
    for (int m = 0; m < system.mesh_count(); ++m)
      for (int t = 0; t < system.mesh(m).triangle_count(); ++t) deepest(m, t);
  }
  for (int m = 0; m < system.mesh_count(); ++m)
    if (mesh_overlap_[m] <= 0.0 && mesh_inside_[m] != std::numeric_limits<double>::max())
      mesh_overlap_[m] = mesh_inside_[m];
  for (int m = 0; m < system.mesh_count(); ++m) {
    const double delta = mesh_overlap_[m];
    if (delta > 0.0) e += hertz(model.pair(p.material[i], system.mesh(m).material()).e_star, r, delta);
  }
  return e;
}

double Breakage::contact_energy(const System& system, std::size_t i) const {
  return contact_energy(system, i, nullptr, nullptr);
}

double Breakage::contact_energies(const System& system, const std::vector<std::size_t>& which) {
  double sum = 0.0;
  if (!system.lists_current()) {
    for (std::size_t i : which) sum += contact_energy(system, i);
    return sum;
  }
  system.neighbor_list().listed_neighbours(which, nb_offsets_, nb_items_);
  for (std::size_t k = 0; k < which.size(); ++k)
    sum += contact_energy(system, which[k], nb_items_.data() + nb_offsets_[k],
                          nb_items_.data() + nb_offsets_[k + 1]);
  return sum;
}

void Breakage::break_particles(System& system, const std::vector<std::size_t>& indices) {
  crush(system, indices, {});
}

void Breakage::crush(System& system, const std::vector<std::size_t>& fragment,
                     const std::vector<std::size_t>& powder) {
  crush(system, fragment, powder, nullptr);
}

void Breakage::crush(System& system, const std::vector<std::size_t>& fragment,
                     const std::vector<std::size_t>& powder,
                     const std::vector<std::int64_t>* first_id) {
  if (fragment.empty() && powder.empty()) return;
  if (first_id != nullptr && first_id->size() != fragment.size())
    throw Error("breakage: " + std::to_string(first_id->size()) + " first ids for " +
                std::to_string(fragment.size()) + " broken particles");
  parents_ = fragment;  // (fragment may be broken_)
  const Particles& p = system.particles();
  const std::size_t n = p.size();
  fragments_.clear();
  std::vector<char> remove(n, 0);
  const int nf = pattern_.size();
  for (std::size_t i : parents_) {
    if (i >= n || remove[i])
      throw Error("break_particles: bad or repeated index " + std::to_string(i));
    remove[i] = 1;
  }
  for (std::size_t i : powder) {
    if (i >= n || remove[i]) throw Error("crush: bad or repeated index " + std::to_string(i));
    remove[i] = 1;
  }
  // the contact energy the parents and the powder had (in the order they are listed)
  added_ = parents_;
  added_.insert(added_.end(), powder.begin(), powder.end());
  double released = 0.0;
  {
    // (summed in the order parents, then powder, each particle's energy added once: as the
    // particles are taken)
    if (system.lists_current()) {
      system.neighbor_list().listed_neighbours(added_, nb_offsets_, nb_items_);
    }
  }
  auto energy_of = [&](std::size_t k) {
    return system.lists_current()
               ? contact_energy(system, added_[k], nb_items_.data() + nb_offsets_[k],
                                nb_items_.data() + nb_offsets_[k + 1])
               : contact_energy(system, added_[k]);
  };
  for (std::size_t k = 0; k < parents_.size(); ++k) {
    const std::size_t i = parents_[k];
    const double e_parent = energy_of(k);
    released += e_parent;
    count(5, e_parent);
    const double r = p.radius[i], mass = p.mass[i], ip = p.inertia[i];
    const Eigen::Vector3d x = p.position[i], v = p.velocity[i], w = p.angular_velocity[i];
    const double rho = system.contact_model().material(p.material[i]).density;
    // random orientation (Shoemake's uniform quaternion from three uniforms)
    const double u1 = uniform(parameters_.seed, p.id[i], 1),
                 u2 = uniform(parameters_.seed, p.id[i], 2),
                 u3 = uniform(parameters_.seed, p.id[i], 3);
    const double two_pi = 2.0 * std::numbers::pi;
    const Eigen::Quaterniond q(
        std::sqrt(u1) * std::cos(two_pi * u3), std::sqrt(1.0 - u1) * std::sin(two_pi * u2),
        std::sqrt(1.0 - u1) * std::cos(two_pi * u2), std::sqrt(u1) * std::sin(two_pi * u3));
    const Eigen::Matrix3d rot = q.normalized().toRotationMatrix();
    const std::size_t first = fragments_.size();
    double m_f = 0.0, j_f = 0.0, i_s = 0.0;  // fragments' mass, orbital and own inertia
    for (int k2 = 0; k2 < nf; ++k2) {
      System::Fragment f;
      const Eigen::Vector3d c = r * (rot * pattern_.centre(k2));
      f.parent = i;
      f.radius = shrink * r * pattern_.radius(k2);
      f.position = x + c;
      f.velocity = v + w.cross(c);  // the parent's rigid motion
      f.angular_velocity = w;
      f.mass = rho * 4.0 / 3.0 * std::numbers::pi * f.radius * f.radius * f.radius;
      f.inertia = 0.4 * f.mass * f.radius * f.radius;
      f.material = p.material[i];
      if (first_id != nullptr) f.id = (*first_id)[k] + k2;
      m_f += f.mass;
      j_f += f.mass * 2.0 / 3.0 * c.squaredNorm();  // isotropic second moment: sum m (|c|^2 I - c c^T)
      i_s += f.inertia;
      fragments_.push_back(f);
    }
    const double missing = mass - m_f;
    const double i_missing = ip - j_f - i_s;  // the lost material's inertia about the centre
    if (parameters_.restore_mass) {
      const double scale = mass / m_f;
      const double extra = std::max(0.0, scale * (ip / scale - j_f - i_s)) / nf;
      for (std::size_t k2 = first; k2 < fragments_.size(); ++k2) {
        fragments_[k2].mass *= scale;
        fragments_[k2].inertia = fragments_[k2].inertia * scale + extra;
      }
      counters_.mass_restored += missing;
      counters_.fragment_mass += mass;
      count(4, missing);
      count(2, mass);
    } else {
      for (std::size_t k2 = first; k2 < fragments_.size(); ++k2) fragments_[k2].mass = 0.0;  // (the material's)
      counters_.mass_lost += missing;
      counters_.fragment_mass += m_f;
      const double carried = 0.5 * missing * v.squaredNorm() + 0.5 * i_missing * w.squaredNorm();
      released += carried;
      count(3, missing);
      count(2, m_f);
      count(5, carried);
    }
    ++counters_.events;
    count(0, 1.0);
  }
  for (std::size_t k = 0; k < powder.size(); ++k) {  // removed whole: their motion and contacts leave with them
    const std::size_t i = powder[k];
    const double e = energy_of(parents_.size() + k) + 0.5 * p.mass[i] * p.velocity[i].squaredNorm() +
                     0.5 * p.inertia[i] * p.angular_velocity[i].squaredNorm();
    ++counters_.powder_events;
    counters_.powder_mass += p.mass[i];
    counters_.powder_energy += e;
    released += e;
    count(6, 1.0);
    count(7, p.mass[i]);
    count(8, e);
    count(5, e);
  }
  const std::size_t first = system.replace_particles(remove, fragments_);
  added_.clear();
  for (std::size_t k = 0; k < fragments_.size(); ++k) {
    added_.push_back(first + k);
    const double d = 2.0 * fragments_[k].radius;
    if (counters_.smallest_fragment == 0.0 || d < counters_.smallest_fragment)
      counters_.smallest_fragment = d;
  }
  ParticleStore& store = system.store_unsynced();
  std::vector<double>& strength = store.array<double>(h_strength_);
  for (std::size_t k : added_) {
    strength[k] = draw_strength(store.core().id[k], 2.0 * store.core().radius[k]);
    set_limit(system, k, strength[k]);
  }
  counters_.fragments += static_cast<std::int64_t>(added_.size());
  count(1, static_cast<double>(added_.size()));
  if (first_id != nullptr) {  // (their contact energy once the ghosts are new: settled())
    counters_.energy_released += released;
    return;
  }
  if (!added_.empty() && system.lists_current()) {
    system.neighbor_list().listed_neighbours(added_, nb_offsets_, nb_items_);
    for (std::size_t k = 0; k < added_.size(); ++k) {
      const double e = contact_energy(system, added_[k], nb_items_.data() + nb_offsets_[k],
                                      nb_items_.data() + nb_offsets_[k + 1]);
      released -= e;
      count(5, -e);
    }
  } else {
    for (std::size_t k : added_) {
      const double e = contact_energy(system, k);
      released -= e;
      count(5, -e);
    }
  }
  counters_.energy_released += released;
}

void Breakage::choose(System& system, const std::vector<char>& skip,
                      std::vector<std::size_t>& replaced, std::vector<std::size_t>& removed) {
  ParticleStore& store = system.store_unsynced();
  const Particles& p = store.core();
  const std::vector<double>& load = system.contact_load();
  const std::size_t n = p.size();
  if (load.size() != n || !system.contact_load_reached()) return;  // (as end_of_step())
  if (skip.size() != n)
    throw Error("breakage: choose() needs one flag per particle (" + std::to_string(n) +
                "), got " + std::to_string(skip.size()));
  std::vector<double>& strength = store.array<double>(h_strength_);
  const std::vector<double>& limit = store.array<double>(h_limit_);
  for (std::size_t i = 0; i < n; ++i) {
    if (strength[i] < 0.0) {  // (a ghost's too: the same draw as its owner's)
      strength[i] = draw_strength(p.id[i], 2.0 * p.radius[i]);
      set_limit(system, i, strength[i]);
    }
    if (!skip[i] && load[i] >= limit[i])
      (2.0 * p.radius[i] >= parameters_.comminution_limit ? replaced : removed).push_back(i);
  }
}

void Breakage::replace(System& system, const std::vector<std::size_t>& replaced,
                       const std::vector<std::size_t>& removed,
                       const std::vector<std::int64_t>& first_id) {
  crush(system, replaced, removed, &first_id);
}

void Breakage::settled(System& system, const std::vector<char>& skip, std::int64_t first_id,
                       std::int64_t end_id) {
  const Particles& p = system.particles();
  if (skip.size() != p.size())
    throw Error("breakage: settled() needs one flag per particle (" + std::to_string(p.size()) +
                "), got " + std::to_string(skip.size()));
  added_.clear();
  for (std::size_t i = 0; i < p.size(); ++i)
    if (!skip[i] && p.id[i] >= first_id && p.id[i] < end_id) added_.push_back(i);
  if (added_.empty()) return;
  const bool listed = system.lists_current();
  if (listed) system.neighbor_list().listed_neighbours(added_, nb_offsets_, nb_items_);
  double released = 0.0;
  for (std::size_t k = 0; k < added_.size(); ++k) {
    const double e =
        listed ? contact_energy(system, added_[k], nb_items_.data() + nb_offsets_[k],
                                nb_items_.data() + nb_offsets_[k + 1])
               : contact_energy(system, added_[k]);
    released -= e;
    count(5, -e);
  }
  counters_.energy_released += released;
}

void Breakage::set_sums(const std::vector<ExactSum>& sums) {
  if (sums.size() != sum_count)
    throw Error("breakage: " + std::to_string(sums.size()) + " counter sums, not " +
                std::to_string(sum_count));
  sums_ = sums;
}

BreakageCounters Breakage::counters_from(const std::vector<double>& t) {
  BreakageCounters c;
  if (t.size() != sum_count)
    throw Error("breakage: " + std::to_string(t.size()) + " counter totals, not " +
                std::to_string(sum_count));
  c.events = static_cast<std::int64_t>(t[0]);
  c.fragments = static_cast<std::int64_t>(t[1]);
  c.fragment_mass = t[2];
  c.mass_lost = t[3];
  c.mass_restored = t[4];
  c.energy_released = t[5];
  c.powder_events = static_cast<std::int64_t>(t[6]);
  c.powder_mass = t[7];
  c.powder_energy = t[8];
  return c;
}

void Breakage::write_state(BinaryWriter& out) const {
  // strengths travel with the particles (store); the draws are counter-based on (seed, id), so
  // the counters are the model's whole state
  out.value(parameters_.seed);
  out.value(counters_);
}

void Breakage::restored(System& system) {
  const std::vector<double>& strength = system.store_unsynced().array<double>(h_strength_);
  for (std::size_t i = 0; i < strength.size(); ++i)
    if (strength[i] >= 0.0) set_limit(system, i, strength[i]);
}

void Breakage::read_state(BinaryReader& in) {
  in.expect(parameters_.seed, "the breakage seed");
  in.value(counters_, "the breakage counters");
  // (the sums restart from the counters; a split bed's restart puts its totals back: set_sums())
  const double c[sum_count] = {static_cast<double>(counters_.events),
                               static_cast<double>(counters_.fragments),
                               counters_.fragment_mass,
                               counters_.mass_lost,
                               counters_.mass_restored,
                               counters_.energy_released,
                               static_cast<double>(counters_.powder_events),
                               counters_.powder_mass,
                               counters_.powder_energy};
  for (std::size_t q = 0; q < sum_count; ++q) {
    sums_[q].clear();
    sums_[q].add(c[q]);
  }
}

}  // namespace partita::dem
