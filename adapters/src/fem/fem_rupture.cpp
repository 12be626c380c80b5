#include "fem_rupture.hpp"

#include <fmt/format.h>
#include <cmath>

#include "partita/fem/error.hpp"
#include "partita/interface/log.hpp"

namespace partita::adapters {

using config::Node;
using config::Spec;

std::shared_ptr<Spec> fem_failure_spec() {
  auto f = std::make_shared<Spec>(
      "failure",
      "rupture: an element has failed when the mean equivalent plastic strain of its quadrature "
      "points reaches eps_f (j2-plasticity only)");
  f->choice("criterion",
            "constant (eps_f = strain) or gl (Germanischer Lloyd, ship collision: eps_f = "
            "uniform_strain + necking_strain * thickness / l_e, l_e the element's in-plane size "
            "sqrt(a1 a2) of its two largest extents; Scharrer, Zhang & Egge 2002)",
            {"constant", "gl"})
      .required();
  f->real("strain", "constant: the failure strain eps_f").positive();
  f->real("thickness", "gl: the plate thickness t").unit("m").positive();
  f->real("uniform_strain", "gl: eps_g (mild steel 0.056)").non_negative().def(0.056);
  f->real("necking_strain", "gl: eps_e (mild steel 0.54)").non_negative().def(0.54);
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
  try {
    if (f.string("criterion") == "constant") {
      if (!f.has("strain")) f.fail("criterion constant needs 'strain' (the failure strain eps_f)");
      if (f.has("thickness")) f["thickness"].fail("thickness belongs to criterion gl");
      return fem::FailureCriterion::constant(f.real("strain"), erosion);
    }
    if (!f.has("thickness"))
      f.fail("criterion gl needs 'thickness' (the plate thickness t of eps_f = eps_g + eps_e t / "
             "l_e)");
    if (f.has("strain")) f["strain"].fail("strain belongs to criterion constant");
    return fem::FailureCriterion::germanischer_lloyd(
        f.real("thickness"), f.real("uniform_strain"), f.real("necking_strain"), erosion);
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
          "{:.4g}, {:.4g}) m, mean equivalent plastic strain {:.4g} >= eps_f {:.4g}{}",
          participant, f->time, f->element, f->region, f->centroid.x(), f->centroid.y(),
          f->centroid.z(), f->plastic_strain, f->failure_strain,
          solver.element_eroded(f->element) ? " (eroded)" : "");
  }
  logger->debug("fem '{}': {} failed elements at t = {:.6g} s", participant, n, solver.time());
  count_ = n;
}

void FailureLog::restored(const fem::StructuralSolver& solver) {
  count_ = solver.failed_elements();
}

}  // namespace partita::adapters
