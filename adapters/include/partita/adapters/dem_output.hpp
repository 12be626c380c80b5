#pragma once
// VTK files of a DEM system (solvers/dem), written by the interface's VTK XML writer: the glue
// between the solver's arrays and interface/vtk_xml.hpp. The DEM adapter writes its frames with
// these; a program that drives a dem::System directly (bench_dem_peers --vtk) may too, and
// bench_vtk times the particle file on arrays of its own.

#include <filesystem>

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

}  // namespace partita::adapters
