#pragma once
// The FEM participant's rigid indenters (YAML `indenters:`): their parameter spec, their
// construction as contact contributions of the FE operator (fem::IndenterContact), their monitor
// quantities and their surfaces offered to other participants as moving meshes.
//
//   indenters:
//     - {name: bow, shape: capsule, radius: 0.5, length: 2, axis: [1, 0, 0],
//        position: [0, 0, 1.6], face: outer, penalty: {factor: 10}, friction: 0.2,
//        motion: {velocity: [0, 0, -5]}}              # driven, constant velocity
//     - {name: ball, shape: sphere, radius: 0.05, position: [..], face: zmax,
//        motion: {mass: 2, velocity: [0, 0, -3], gravity: [0, 0, -9.81]}}   # free
//
// Monitors per indenter N (declared in fem_monitors.cpp): N.x|y|z (its reference point:
// `position` plus its displacement), N.vx|vy|vz, N.force_x|y|z (the contact force on it),
// N.penetration, N.work (done on the structure), N.external_force_x|y|z and N.external_work (a
// free indenter), N.kinetic_energy, N.contact_energy (penalty springs), N.friction_work
// (dissipated), N.contact_nodes.

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "partita/fem/indenter_contact.hpp"
#include "partita/fem/model.hpp"
#include "partita/interface/config.hpp"
#include "partita/interface/vtk_xml.hpp"
#include "partita/interface/solver.hpp"

namespace partita::adapters {

std::shared_ptr<config::Spec> indenter_spec();

// One indenter of the case, built: the contribution to hand to the solver, and what the
// adapter keeps (name, reference point, surface mesh for other participants).
struct IndenterBuild {
  std::string name;
  Eigen::Vector3d reference = Eigen::Vector3d::Zero();
  std::unique_ptr<fem::IndenterContact> contact;
  bool has_surface = false;  // a bounded shape: its triangulation is offered as a mesh
  InterfaceMesh surface;     // named after the indenter; writes "displacement"
};

// Builds the indenter of `node` (validated by indenter_spec()) against the model; `transient`
// and `explicit_steps` tell which motions are allowed (a free indenter needs central difference).
// Errors name the key (node.fail).
IndenterBuild build_indenter(const config::Node& node, const fem::Model& model,
                             const std::filesystem::path& case_dir, bool explicit_steps);

// The indenter's surface where it is now, with its displacement, as VTK PolyData (a frame of the
// series <participant>_<name>).
void write_indenter_vtp(const std::filesystem::path& file, const InterfaceMesh& surface,
                        const fem::IndenterContact& contact, const vtk::Options& options);

}  // namespace partita::adapters
