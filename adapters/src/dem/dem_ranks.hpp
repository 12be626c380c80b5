#pragma once
// The DEM adapter's state on several ranks (dem_ranks.cpp says how the split runs): the bed split
// into one subdomain a rank (dem::SubdomainStepper over dem::MpiSubdomainTransport), and the
// monitor values of the last collective pass.

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "dem_adapter.hpp"
#include "partita/dem/breakage_counters.hpp"
#include "partita/dem/domain_decomposition.hpp"
#include "partita/dem/subdomain.hpp"
#include "partita/dem/subdomain_transport.hpp"
#include "partita/interface/participant_ranks.hpp"

namespace partita::adapters {

struct DemAdapter::OnRanks {
  // what a read or write of coupled data carries
  static constexpr std::uint32_t kDisplacement = 1, kAttached = 2, kVertexForce = 3,
                                 kTriangleForce = 4, kTraction = 5;
  std::shared_ptr<ParticipantRanks> ranks;
  std::unique_ptr<dem::SubdomainTransport> transport;  // MpiSubdomainTransport
  std::unique_ptr<dem::SubdomainStepper> stepper;      // over the adapter's System
  dem::DomainDecomposition decomposition;              // the boxes (the last cut)
  double skin = 0.0;
  bool started = false;  // the stepper's start() or resume() done
  bool forces = false;   // a force pass since the start or the resume (forces to report)
  bool ended = false;    // (rank 0) the others were told the run has ended
  long rebalances = 0;   // cuts made again as the load drifted (DemAdapter::ranks_rebalance())
  // over every particle: at the start, and again after a step in which breakage changed the set
  // (the stepper's replacement_steps() moved on from `replacements`)
  double particles = 0.0, mass = 0.0, stable = 0.0;
  long replacements = 0;
  // (breakage) its counters summed over the ranks at the last monitors pass
  dem::BreakageCounters breakage;
  // the energy accounting (energy_accounting: true): the split's books (SubdomainStepper::
  // set_energy_accounting(); the System keeps none of its own on a split)
  bool books = false;
  // the monitors' values of the last collective pass (rank 0)
  double kinetic = 0.0, elastic = 0.0, contacts_per_particle = 0.0;
  dem::System::Energies energies;  // (books) and their balance
  double balance = 0.0;
  Eigen::Vector3d momentum = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> wall_force;                 // by walls_ index
  std::vector<std::array<Eigen::Vector3d, 6>> face_force;  // by walls_ index, face (a box's)
  std::vector<Eigen::Vector3d> mesh_force;                 // by meshes_dem_ index
  // the coupled meshes (by meshes_dem_ index): whether a displacement was read (from then on
  // every step adds the motion's work to the audit, from the forces summed over the ranks), and
  // (the leader) the last `attached` values passed on (mostly unchanged: not sent again)
  std::vector<char> moved;
  std::vector<Eigen::MatrixXd> attached;
  // (the leader) what read() took since the last command, passed on ahead of the next one
  std::vector<std::byte> pending;
  std::size_t meshes_received = 0;  // of the requested ones (the split waits for all)
  Eigen::MatrixXd values;           // (the others) a read's or write's values
  std::string checkpoint;           // (the leader) the split bed at save_checkpoint()
  // the transport's buffers (one local subdomain)
  std::vector<dem::SubdomainMail> out, in;
};

}  // namespace partita::adapters
