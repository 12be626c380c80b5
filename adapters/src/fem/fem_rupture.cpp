#include "fem_rupture.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "partita/fem/error.hpp"
#include "partita/interface/log.hpp"

namespace partita::adapters {

using config::Node;
using config::Spec;

std::shared_ptr<Spec> fem_failure_spec() {
  auto f = std::make_shared<Spec>(
      "failure",
      "rupture: an element has failed when the mean equivalent plastic strain of its quadrature "
      "points reaches eps_f (constant, gl), or the mean damage of its points reaches 1 (rtcl, "
      "bwh); j2-plasticity only");
  f->choice("criterion",
            "constant (eps_f = strain) or gl (Germanischer Lloyd, ship collision: eps_f = "
            "uniform_strain + necking_strain * thickness / l_e, l_e the element's in-plane size "
            "sqrt(a1 a2) of its two largest extents; Scharrer, Zhang & Egge 2002); rtcl "
            "(Rice-Tracey/Cockcroft-Latham damage D = int f(T) d eps_p / eps_cr by the stress "
            "triaxiality T; Toernqvist 2003) or bwh (Bressan-Williams-Hill local necking limit "
            "of the plate's in-plane stresses, plane stress, hexahedra; Alsos et al. 2008)",
            {"constant", "gl", "rtcl", "bwh"})
      .required();
  f->real("strain", "constant: the failure strain eps_f").positive();
  f->real("thickness",
          "gl: the plate thickness t; rtcl, bwh: t of the size scaling n + (neck_strain - n) "
          "t / l_e (with hardening_exponent and neck_strain)")
      .unit("m")
      .positive();
  f->real("uniform_strain", "gl: eps_g (mild steel 0.056)").non_negative().def(0.056);
  f->real("necking_strain", "gl: eps_e (mild steel 0.54)").non_negative().def(0.54);
  f->real("critical_strain",
          "rtcl: eps_cr, the failure strain of uniaxial tension at this mesh (instead of the "
          "size scaling)")
      .positive();
  f->real("hardening_exponent",
          "rtcl (size scaling), bwh: n of the power law sigma = K eps^n (the uniform strain)")
      .positive();
  f->real("strength_coefficient", "bwh: K of the power law sigma = K eps^n").unit("Pa").positive();
  f->real("neck_strain",
          "rtcl, bwh size scaling: eps_n, the strain in the neck at fracture of a tensile test "
          "(gauge length about t)")
      .positive();
  f->boolean("erosion",
             "remove failed elements from the internal force and the lumped mass, their energy "
             "kept as eroded_energy (central-difference only)")
      .def(false);
  return f;
}

std::shared_ptr<Spec> fem_box_region_spec() {
  auto r = std::make_shared<Spec>(
      "region", "an element region of a box mesh: the elements whose centre lies in [from, to]");
  r->string("name", "region name (monitors <participant>.<name>.plastic_work ...)").required();
  r->reals("from", "lower corner").unit("m").size(3).required();
  r->reals("to", "upper corner").unit("m").size(3).required();
  return r;
}

fem::FailureCriterion build_failure_criterion(const Node& material) {
  if (!material.has("failure")) return {};
  const Node f = material["failure"];
  const bool erosion = f.boolean("erosion");
  const std::string criterion = f.string("criterion");
  // the keys each criterion takes (besides criterion and erosion): any other is refused by name
  const std::vector<std::pair<std::string, std::vector<std::string>>> keys = {
      {"constant", {"strain"}},
      {"gl", {"thickness", "uniform_strain", "necking_strain"}},
      {"rtcl", {"critical_strain", "thickness", "hardening_exponent", "neck_strain"}},
      {"bwh", {"strength_coefficient", "hardening_exponent", "thickness", "neck_strain"}}};
  for (const std::string& key : f.keys()) {
    if (key == "criterion" || key == "erosion") continue;
    std::vector<std::string> takers;
    bool ours = false;
    for (const auto& [name, list] : keys) {
      if (std::find(list.begin(), list.end(), key) == list.end()) continue;
      if (name == criterion) ours = true;
      takers.push_back(name);
    }
    if (!ours && !takers.empty())
      f[key].fail(fmt::format("{} belongs to criterion {}, not {}", key,
                              fmt::join(takers, " or "), criterion));
  }
  try {
    if (criterion == "constant") {
      if (!f.has("strain")) f.fail("criterion constant needs 'strain' (the failure strain eps_f)");
      return fem::FailureCriterion::constant(f.real("strain"), erosion);
    }
    if (criterion == "gl") {
      if (!f.has("thickness"))
        f.fail("criterion gl needs 'thickness' (the plate thickness t of eps_f = eps_g + eps_e t "
               "/ l_e)");
      return fem::FailureCriterion::germanischer_lloyd(
          f.real("thickness"), f.real("uniform_strain"), f.real("necking_strain"), erosion);
    }
    const bool scaled = f.has("thickness") || f.has("neck_strain");
    if (scaled) {
      for (const char* key : {"thickness", "neck_strain", "hardening_exponent"})
        if (!f.has(key))
          f.fail(fmt::format("criterion {} with the size scaling n + (eps_n - n) t / l_e needs "
                             "'{}' (thickness t, neck_strain eps_n and hardening_exponent n)",
                             criterion, key));
    }
    if (criterion == "rtcl") {
      if (f.has("critical_strain")) {
        if (scaled)
          f["critical_strain"].fail("critical_strain (eps_cr given) and the size scaling "
                                    "(thickness, neck_strain) exclude each other: give one");
        if (f.has("hardening_exponent"))
          f["hardening_exponent"].fail(
              "hardening_exponent is for the size scaling; with critical_strain it is unused");
        return fem::FailureCriterion::rtcl(f.real("critical_strain"), erosion);
      }
      if (!scaled)
        f.fail("criterion rtcl needs 'critical_strain' (eps_cr, the failure strain of uniaxial "
               "tension) or the size scaling eps_cr = n + (eps_n - n) t / l_e ('thickness', "
               "'hardening_exponent', 'neck_strain')");
      return fem::FailureCriterion::rtcl_scaled(f.real("thickness"), f.real("hardening_exponent"),
                                                f.real("neck_strain"), erosion);
    }
    for (const char* key : {"strength_coefficient", "hardening_exponent"})
      if (!f.has(key))
        f.fail(fmt::format("criterion bwh needs '{}' (the power law sigma = K eps^n: "
                           "strength_coefficient K, hardening_exponent n)",
                           key));
    return fem::FailureCriterion::bwh(f.real("strength_coefficient"), f.real("hardening_exponent"),
                                      scaled ? f.real("thickness") : 0.0,
                                      scaled ? f.real("neck_strain") : 0.0, erosion);
  } catch (const fem::Error& e) {
    f.fail(e.what());
  }
}

void check_failure_keys(const Node& material, bool explicit_dynamics) {
  if (!material.has("failure")) return;
  const std::string model = material.string("model");
  if (model.rfind("j2-plasticity", 0) != 0)
    material["failure"].fail("a failure criterion needs plastic strain: material.model '" + model +
                             "' has none and would never fail; use j2-plasticity or "
                             "j2-plasticity-finite-strain");
  if (material["failure"].boolean("erosion") && !explicit_dynamics)
    material["failure"]["erosion"].fail(
        "element erosion works in central-difference analyses only (analysis: {type: "
        "transient, integrator: central-difference, mass: lumped}): static and Newmark solves "
        "would factorise a tangent whose eroded parts float free; set erosion: false to have "
        "failures reported only");
}

void apply_box_regions(fem::Mesh& mesh, const Node& box) {
  if (!box.has("regions")) return;
  for (const Node& r : box["regions"].items()) {
    const std::string name = r.string("name");
    if (name == "all") r["name"].fail("'all' is the region of the elements no other region holds");
    const fem::Vec3 lo = r.vec3("from"), hi = r.vec3("to");
    const std::size_t n = mesh.assign_region_where(name, [&](const fem::Vec3& c) {
      return (c.array() >= lo.array()).all() && (c.array() <= hi.array()).all();
    });
    if (n == 0)
      r.fail(fmt::format("region '{}': no element has its centre in [({}, {}, {}), ({}, {}, {})]",
                         name, lo.x(), lo.y(), lo.z(), hi.x(), hi.y(), hi.z()));
  }
}

void FailureLog::after_step(const fem::StructuralSolver& solver, const std::string& participant) {
  const std::size_t n = solver.failed_elements();
  if (n == count_) return;
  auto logger = log::get("adapters");
  if (count_ == 0) {
    if (const auto f = solver.first_failure())
      logger->info(
          "fem '{}': first failure at t = {:.6g} s: element {} of part '{}', centre ({:.4g}, "
          "{:.4g}, {:.4g}) m, mean equivalent plastic strain {:.4g}{}{}",
          participant, f->time, f->element, f->region, f->centroid.x(), f->centroid.y(),
          f->centroid.z(), f->plastic_strain,
          f->damage >= 0.0 ? fmt::format(", mean damage {:.4g} >= 1", f->damage)
                           : fmt::format(" >= eps_f {:.4g}", f->failure_strain),
          solver.element_eroded(f->element) ? " (eroded)" : "");
  }
  logger->debug("fem '{}': {} failed elements at t = {:.6g} s", participant, n, solver.time());
  count_ = n;
}

void FailureLog::restored(const fem::StructuralSolver& solver) {
  count_ = solver.failed_elements();
}

}  // namespace partita::adapters
