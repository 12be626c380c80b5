#include "partita/dem/contact_model.hpp"

#include "partita/dem/error.hpp"
#include "partita/dem/restitution_calibration.hpp"

#include <map>
#include <sstream>

namespace partita::dem {

int ContactModel::add_material(const Material& m) {
  std::ostringstream msg;
  if (!(m.youngs_modulus > 0.0) || !std::isfinite(m.youngs_modulus))
    msg << "material: Young's modulus must be > 0 Pa, got " << m.youngs_modulus;
  else if (!(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5))
    msg << "material: Poisson's ratio must be in (-1, 0.5), got " << m.poisson_ratio;
  else if (!(m.density > 0.0) || !std::isfinite(m.density))
    msg << "material: density must be > 0 kg/m^3, got " << m.density;
  if (!msg.str().empty()) throw Error(msg.str());
  const int old_n = material_count();
  materials_.push_back(m);
  const int n = old_n + 1;
  std::vector<Interaction> inter(n * n);
  std::vector<bool> set(n * n, false);
  for (int a = 0; a < old_n; ++a)
    for (int b = 0; b < old_n; ++b) {
      inter[a * n + b] = interactions_[a * old_n + b];
      set[a * n + b] = interaction_set_[a * old_n + b];
    }
  interactions_ = std::move(inter);
  interaction_set_ = std::move(set);
  dirty_ = true;
  return old_n;
}

const Material& ContactModel::material(int id) const {
  check_material(id, "material");
  return materials_[id];
}

void ContactModel::check_material(int id, const std::string& what) const {
  if (id < 0 || id >= material_count()) {
    std::ostringstream msg;
    msg << what << ": unknown material id " << id;
    if (material_count() == 0)
      msg << "; no material defined yet (call add_material first)";
    else
      msg << "; defined ids are 0.." << material_count() - 1;
    throw Error(msg.str());
  }
}

void ContactModel::set_interaction(int a, int b, const Interaction& in) {
  check_material(a, "add_interaction");
  check_material(b, "add_interaction");
  std::ostringstream msg;
  if (!(in.friction >= 0.0) || !std::isfinite(in.friction))
    msg << "interaction (" << a << ", " << b << "): friction must be >= 0, got " << in.friction;
  else if (!(in.restitution > 0.0 && in.restitution <= 1.0))
    msg << "interaction (" << a << ", " << b << "): restitution must be in (0, 1], got "
        << in.restitution;
  else if (!(in.rolling_friction >= 0.0) || !std::isfinite(in.rolling_friction))
    msg << "interaction (" << a << ", " << b << "): rolling friction must be >= 0, got "
        << in.rolling_friction;
  if (!msg.str().empty()) throw Error(msg.str());
  const int n = material_count();
  interactions_[a * n + b] = in;
  interactions_[b * n + a] = in;
  interaction_set_[a * n + b] = true;
  interaction_set_[b * n + a] = true;
  dirty_ = true;
}

void ContactModel::set_damping_model(DampingModel model) {
  if (model != damping_model_) dirty_ = true;
  damping_model_ = model;
}

bool ContactModel::has_interaction(int a, int b) const {
  const int n = material_count();
  return a >= 0 && b >= 0 && a < n && b < n && interaction_set_[a * n + b];
}

void ContactModel::update() {
  if (!dirty_) return;
  const int n = material_count();
  std::vector<PairParameters> table(n * n);
  std::map<double, double> zeta_of_e;  // calibration is costly: once per distinct e
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      PairParameters& p = table[a * n + b];
      const Material& ma = materials_[a];
      const Material& mb = materials_[b];
      p.e_star = 1.0 / ((1.0 - ma.poisson_ratio * ma.poisson_ratio) / ma.youngs_modulus +
                        (1.0 - mb.poisson_ratio * mb.poisson_ratio) / mb.youngs_modulus);
      p.g_star =
          1.0 / (2.0 * (2.0 - ma.poisson_ratio) * (1.0 + ma.poisson_ratio) / ma.youngs_modulus +
                 2.0 * (2.0 - mb.poisson_ratio) * (1.0 + mb.poisson_ratio) / mb.youngs_modulus);
      p.st_over_sn_sqrt = std::sqrt(4.0 * p.g_star / p.e_star);
      p.defined = interaction_set_[a * n + b];
      if (!p.defined) continue;
      const Interaction& in = interactions_[a * n + b];
      p.friction = in.friction;
      p.rolling_friction = in.rolling_friction;
      if (damping_model_ == DampingModel::liggghts) {
        p.zeta = RestitutionCalibration::liggghts_damping_ratio(in.restitution);
        p.no_tension = false;
        p.cap_total_tangential = false;
      } else {
        auto it = zeta_of_e.find(in.restitution);
        if (it == zeta_of_e.end())
          it = zeta_of_e
                   .emplace(in.restitution,
                            RestitutionCalibration::damping_ratio(in.restitution, true))
                   .first;
        p.zeta = it->second;
        p.no_tension = true;
        p.cap_total_tangential = true;
      }
    }
  table_ = std::move(table);
  n_ = n;
  dirty_ = false;
}

}  // namespace partita::dem
