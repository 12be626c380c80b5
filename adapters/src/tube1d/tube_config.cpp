#include "tube_config.hpp"

#include <cmath>
#include <numbers>

namespace partita::adapters {

std::shared_ptr<const config::Spec> tube_spec(const char* name, const char* doc, bool fluid) {
  const tube1d::TubeParameters d;
  auto s = std::make_shared<config::Spec>(name, doc);
  s->integer("cells", "number of cells N (the mesh 'nodes' has N + 1 points on the x axis)")
      .min(3)
      .def(d.cells);
  s->real("length", "tube length L").unit("m").positive().def(d.length);
  s->real("youngs_modulus", "Young's modulus E of the wall (c^2 = E / (2 rho r0))")
      .unit("Pa")
      .positive()
      .def(d.youngs_modulus);
  s->real("radius", "reference radius r0").unit("m").positive().def(d.radius);
  s->real("reference_area", "cross-section area a0 at the reference pressure")
      .unit("m^2")
      .positive()
      .def(d.reference_area);
  s->real("reference_pressure", "reference pressure p0").unit("Pa").def(d.reference_pressure);
  s->real("density", "fluid density rho").unit("kg/m^3").positive().def(d.density);
  s->real("initial_pressure", "initial pressure at every node").unit("Pa").def(d.initial_pressure);
  if (fluid) {
    s->real("inlet_velocity", "mean inlet velocity u_in").unit("m/s").def(d.inlet_velocity);
    s->real("inlet_amplitude", "amplitude A of u_in + A sin(2 pi f t)")
        .unit("m/s")
        .def(d.inlet_amplitude);
    s->real("inlet_frequency", "frequency f of the inlet velocity")
        .unit("Hz")
        .non_negative()
        .def(d.inlet_frequency);
    s->real("initial_velocity", "initial velocity at every node")
        .unit("m/s")
        .def(d.initial_velocity);
  }
  return s;
}

tube1d::TubeParameters tube_parameters(const config::Node& n, bool fluid) {
  tube1d::TubeParameters p;
  p.cells = static_cast<int>(n.integer("cells"));
  p.length = n.real("length");
  p.youngs_modulus = n.real("youngs_modulus");
  p.radius = n.real("radius");
  p.reference_area = n.real("reference_area");
  p.reference_pressure = n.real("reference_pressure");
  p.density = n.real("density");
  p.initial_pressure = n.real("initial_pressure");
  if (fluid) {
    p.inlet_velocity = n.real("inlet_velocity");
    p.inlet_amplitude = n.real("inlet_amplitude");
    p.inlet_frequency = n.real("inlet_frequency");
    p.initial_velocity = n.real("initial_velocity");
  }
  if (2.0 * p.density * p.wave_speed_squared() <= p.initial_pressure)
    n["initial_pressure"].fail("the initial pressure must stay below 2 rho c^2 = E / r0 = " +
                               std::to_string(p.youngs_modulus / p.radius) +
                               " Pa (the tube law's pole)");
  return p;
}

}  // namespace partita::adapters
