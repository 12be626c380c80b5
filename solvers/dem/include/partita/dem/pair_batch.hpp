#pragma once
// The pair forces of a block of rows, several pairs at a time in the lanes of vector registers.
//
// The force pass (System::evaluate_forces_impl) first lists the touching pairs of a block of 64
// rows without branching on the overlap test, then hands the list to one of these kernels, then
// adds the forces row by row in the usual order. Why: a contact's force is a chain of dependent
// square roots and divisions (|d|, 1/|d|, sqrt(R* delta), sqrt(S_n m*), the friction cap), and the
// overlap test before it is a coin flip for the branch predictor (4.0 listed pairs a particle,
// 2.3 touching, on the large peer bed). In lanes, several chains run per instruction and the
// per-material branches of the law (no tension, friction off, the two tangential caps, rolling
// resistance) are taken lane by lane with masks.
//
// The lanes do the operations of the scalar kernel (PairContacts::force() with hertz_mindlin())
// in the same order, so every result has the same bits whatever the kernel set
// (tests/solvers/dem/test_pair_batch.cpp checks it on random contacts of every branch): pairs
// evaluated by the scalar kernel (across threads' parts) and by these sum alike, and results do
// not depend on the thread count or on the machine's instruction sets. Built with
// -ffp-contract=off (no fused multiply-add) like the scalar kernel.
//
// Kernel sets: "avx512" (8 lanes), "avx2" (4 lanes), chosen at run time by what the CPU has, and
// the portable "sse2" (2 lanes); the environment variable PARTITA_DEM_PAIR_KERNELS=sse2|avx2
// forces a smaller one (ctest runs the DEM tests once more with each).

#include "partita/dem/contact_model.hpp"
#include "partita/dem/packed_particle.hpp"

#include <Eigen/Core>

namespace partita::dem {

/// A touching pair (i, j) of the half list, slot s (its tangential history: shear[s]).
struct PairTask {
  int s, i, j;
};

/// A kernel's result for one pair: force on i (j gets its negative), torques on i and j, and
/// the contact load of the breakage criterion (Load kernels only).
struct PairForce {
  double f[3];
  double ti[3];
  double tj[3];
  double load;
};

/// The dissipative parts of a pair's force (energy kernels only; DissipativeParts): damping force
/// on i and the damping torques on i and j (with rolling resistance), friction force on i and its
/// torques, and the spring energy the friction cap released.
struct PairEnergy {
  double fd[3];
  double tdi[3];
  double tdj[3];
  double ff[3];
  double tfi[3];
  double tfj[3];
  double spring;
  double stiffening;
  double plastic;  ///< work of the pair's yield in this pass (an energy) [J]
};

/// Evaluates the touching pairs tasks[0, n) into out[0, n) and updates their histories
/// shear[tasks[k].s] as PairContacts::force() does for a pair known to overlap (the caller marks
/// their slots touching). mass and material: the store's arrays. energy: the dissipative parts
/// into energy[0, n) (the energy kernels; ignored by the others). yield: the particles that
/// yield and the pairs' permanent overlaps (nullptr: none; PairContacts::force()'s plastic).
using PairBatchKernel = void (*)(const PairTask* tasks, int n, const PackedParticle* packed,
                                 const double* mass, const int* material, const ContactModel& model,
                                 Eigen::Vector3d* shear, double dt, bool update_history,
                                 PairForce* out, PairEnergy* energy, const PairYield* yield);

struct PairBatchKernels {
  const char* name;  ///< "avx512", "avx2" or "sse2"
  int lanes;
  PairBatchKernel plain;
  PairBatchKernel with_load;  ///< also writes PairForce::load
  PairBatchKernel plain_energy;      ///< plain + PairEnergy
  PairBatchKernel with_load_energy;  ///< with_load + PairEnergy
};

/// The widest kernel set this CPU runs (or the one PARTITA_DEM_PAIR_KERNELS names, if the CPU
/// has it); chosen once.
const PairBatchKernels& pair_batch_kernels();
/// Every kernel set this CPU runs, widest first (tests).
int pair_batch_kernel_sets(const PairBatchKernels** sets, int capacity);

}  // namespace partita::dem
