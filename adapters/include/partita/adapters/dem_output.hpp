#pragma once
// VTK files of a DEM system (solvers/dem), written by the interface's VTK XML writer: the glue
// between the solver's arrays and interface/vtk_xml.hpp. The DEM adapter writes its frames with
// these; a program that drives a dem::System directly (bench_dem_peers --vtk) may too, and
// bench_vtk times the particle file on arrays of its own.

#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "partita/interface/vtk_xml.hpp"

namespace partita::dem {
class System;
struct Particles;
}  // namespace partita::dem

namespace partita::adapters {

/// The particles as vertices (.vtp): point arrays radius [m], id (Int64), velocity [m/s],
/// angular_velocity [rad/s], force [N] (Float64), written from the solver's arrays (no copy).
void write_particles_vtp(const dem::System& system, const std::filesystem::path& path,
                         const vtk::Options& options);
void write_particles_vtp(const dem::Particles& particles, const std::filesystem::path& path,
                         const vtk::Options& options);

/// Mesh `mesh` of the system as triangles (.vtp): point arrays velocity [m/s] and force [N] (the
/// particles' force on each vertex), cell array force [N] (on each triangle).
void write_mesh_vtp(const dem::System& system, int mesh, const std::filesystem::path& path,
                    const vtk::Options& options);
/// The same with the forces given (vertices x 3 and triangles x 3 [N]: a bed split over ranks
/// sums them over the ranks).
void write_mesh_vtp(const dem::System& system, int mesh, const std::filesystem::path& path,
                    const vtk::Options& options, const Eigen::MatrixX3d& vertex_forces,
                    const Eigen::MatrixX3d& triangle_forces);

/// The particles of a bed split over ranks as one parallel PolyData file (.pvtp) whose pieces
/// are `pieces` (file names beside it, each written by write_particles_vtp() with the same
/// options): ParaView opens the pieces as one data set. Written atomically.
void write_particles_pvtp(const std::filesystem::path& path, const std::vector<std::string>& pieces,
                          const vtk::Options& options);
/// Removes the pieces <prefix>_particles_<frame>_<rank>.vtp in `directory` (those of an earlier
/// run on ranks: the .pvd series an earlier run leaves lists its .pvtp files, whose removal leaves
/// the pieces); returns how many.
int remove_particle_pieces(const std::filesystem::path& directory, const std::string& prefix);

}  // namespace partita::adapters
