#pragma once
// Shared helpers of the partita::fem tests (not a test file itself).
#include <cmath>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include <catch2/catch.hpp>

#include "partita/fem/box_mesher.hpp"
#include "partita/fem/element_topology.hpp"
#include "partita/fem/mesh.hpp"
#include "partita/fem/structural_solver.hpp"

namespace partita::fem::test {

// Deterministic pseudo-random numbers in [-1, 1].
class Lcg {
 public:
  explicit Lcg(unsigned long long seed) : s_(seed) {}
  double next() {
    s_ = s_ * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(s_ >> 11) / static_cast<double>(1ull << 53) * 2.0 - 1.0;
  }

 private:
  unsigned long long s_;
};

// The seed plate of bench_fem_plate (20 x 20 x 2 mm steel, E = 250 GPa, nu = 0.3, rho = 7850;
// lateral nodes fixed in x and y, bottom corners in z, 10 kPa on the top face: the corners carry
// p A = 4 N), n x n x nz Hex8 cells.
// The 7-point Laplacian of an nx x ny x nz grid plus shift times the identity (SPD for
// shift > 0), both triangles stored: nested dissection gives it a deep tree with large top
// separators (the threaded solve's and factorisation's tests).
inline SparseMatrix grid_laplacian(int nx, int ny, int nz, double shift = 0.01) {
  const int n = nx * ny * nz;
  auto id = [&](int i, int j, int k) { return (k * ny + j) * nx + i; };
  std::vector<Eigen::Triplet<double>> t;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const int a = id(i, j, k);
        t.emplace_back(a, a, 6.0 + shift);
        if (i + 1 < nx)
          t.emplace_back(a, id(i + 1, j, k), -1.0), t.emplace_back(id(i + 1, j, k), a, -1.0);
        if (j + 1 < ny)
          t.emplace_back(a, id(i, j + 1, k), -1.0), t.emplace_back(id(i, j + 1, k), a, -1.0);
        if (k + 1 < nz)
          t.emplace_back(a, id(i, j, k + 1), -1.0), t.emplace_back(id(i, j, k + 1), a, -1.0);
      }
  SparseMatrix a(n, n);
  a.setFromTriplets(t.begin(), t.end());
  return a;
}

// a solution with every digit in play
inline Eigen::VectorXd known_solution(Eigen::Index n) {
  Eigen::VectorXd x(n);
  for (Eigen::Index i = 0; i < n; ++i) x[i] = std::sin(0.37 * static_cast<double>(i)) + 0.5;
  return x;
}

inline double relative_difference(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return (a - b).norm() / b.norm();
}

inline int threads_available() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

inline void use_threads(int n) {
#ifdef _OPENMP
  omp_set_num_threads(n);
#else
  (void)n;
#endif
}

inline Model seed_plate(int n, int nz) {
  const double lx = 0.02, ly = 0.02, tol = 1e-12;
  Mesh mesh = make_box_mesh({Vec3::Zero(), Vec3(lx, ly, 0.002), {n, n, nz}, ElementType::Hex8});
  mesh.add_node_set_where("lateral", [&](const Vec3& x) {
    return x[0] < tol || x[0] > lx - tol || x[1] < tol || x[1] > ly - tol;
  });
  mesh.add_node_set_where("corners", [&](const Vec3& x) {
    return x[2] < tol && (x[0] < tol || x[0] > lx - tol) && (x[1] < tol || x[1] > ly - tol);
  });
  Model model(mesh, Material{250e9, 0.3, 7850});
  model.fix("lateral", {0, 1});
  model.fix("corners", {2});
  model.add_pressure("zmax", 10e3);
  return model;
}

// Union of node sets.
inline void add_union_set(Mesh& mesh, const std::string& name,
                          const std::vector<std::string>& sets) {
  std::vector<std::size_t> ids;
  for (const auto& s : sets)
    ids.insert(ids.end(), mesh.node_set(s).begin(), mesh.node_set(s).end());
  mesh.add_node_set(name, ids);
}

// Places the edge nodes of quadratic elements at the midpoints of their corners.
inline void straighten_edges(Mesh& mesh) {
  for (const auto& e : mesh.elements()) {
    const int nc = corner_count(e.type);
    const auto edges = quadratic_edges(e.type);
    for (std::size_t k = 0; k < edges.size(); ++k) {
      mesh.set_node(e.nodes[nc + k],
                    0.5 * (mesh.node(e.nodes[edges[k][0]]) + mesh.node(e.nodes[edges[k][1]])));
    }
  }
}

// Moves every node not on the box boundary by up to `amount` (fraction of the cell size h) in
// each direction, then straightens the edges of quadratic elements.
inline void distort_interior(Mesh& mesh, const BoxSpec& spec, double amount,
                             unsigned long long seed) {
  Lcg rng(seed);
  const Vec3 lo = spec.origin, hi = spec.origin + spec.size;
  for (std::size_t i = 0; i < mesh.num_nodes(); ++i) {
    Vec3 x = mesh.node(i);
    bool boundary = false;
    for (int d = 0; d < 3; ++d)
      boundary = boundary || std::abs(x[d] - lo[d]) < 1e-12 || std::abs(x[d] - hi[d]) < 1e-12;
    if (boundary) continue;
    for (int d = 0; d < 3; ++d) x[d] += amount * spec.size[d] / spec.cells[d] * rng.next();
    mesh.set_node(i, x);
  }
  straighten_edges(mesh);
}

// Explicit stability probe of a rod along x: one step of dt under random axial nodal forces
// (random initial accelerations), then `steps` free steps; true when the motion grew beyond
// 1e3 times its size after the kick (unstable) or stopped being finite.
inline bool axial_kick_grows(StructuralSolver& s, double dt, int steps) {
  Lcg rng(1);
  std::vector<std::size_t> nodes;
  MatrixX3 f(static_cast<Eigen::Index>(s.mesh().num_nodes()), 3);
  for (std::size_t i = 0; i < s.mesh().num_nodes(); ++i) {
    nodes.push_back(i);
    f.row(static_cast<Eigen::Index>(i)) = Vec3(1e3 * rng.next(), 0, 0).transpose();
  }
  s.set_nodal_forces(nodes, f);
  s.step(dt);
  s.clear_coupling_loads();
  const double u0 = s.max_displacement();
  for (int k = 0; k < steps; ++k) s.step(dt);
  return !s.displacement().allFinite() || !(s.max_displacement() < 1e3 * u0);
}

// The 1D (uniaxial-strain) wave speed sqrt((lambda + 2 mu) / rho).
inline double dilatational_speed(double e, double nu, double rho) {
  const double lambda = e * nu / ((1 + nu) * (1 - 2 * nu)), mu = e / (2 * (1 + nu));
  return std::sqrt((lambda + 2 * mu) / rho);
}

// Rod [0, L] x [0, a]^2 of n Hex8 along x in uniaxial strain (y and z fixed everywhere), so
// that waves travel along x at c_d = dilatational_speed() (1D wave equation); for a >= L / n
// each element's stable step (its free dofs are axial) is (L / n) / c_d exactly.
inline Model uniaxial_rod(double length, int n, double a, const Material& material) {
  Model m(make_box_mesh({Vec3::Zero(), Vec3(length, a, a), {n, 1, 1}, ElementType::Hex8}),
          material);
  m.fix("all", {1, 2});
  return m;
}

/// run() (a solve, returning x) on 1, 2, 3 and 4 threads, three times each, gives the bits of
/// `reference`; the thread count is restored afterwards.
template <class Run>
void check_same_bits_on_threads(const Eigen::VectorXd& reference, Run run) {
  const int before = threads_available();
  for (int threads : {1, 2, 3, 4}) {
    use_threads(threads);
    for (int repeat = 0; repeat < 3; ++repeat) {
      const Eigen::VectorXd x = run();
      INFO(threads << " threads, repeat " << repeat);
      CHECK((x.array() == reference.array()).all());
    }
  }
  use_threads(before);
}

}  // namespace partita::fem::test
