#pragma once
// Reader and writer of particle files (LAMMPS data format, atom_style sphere; the peer-benchmark
// bed files and the DEM's own final states):
//   header lines "N atoms", "xlo xhi" / "ylo yhi" / "zlo zhi",
//   "Atoms" section: id type diameter density x y z   (SI units; extra columns ignored)
//   optional "Velocities" section: id vx vy vz wx wy wz, one line per atom (a partial section
//   is an error, as in LAMMPS: the atoms it leaves out would start at rest without a word)
// Other sections are skipped; '#' starts a comment.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace partita::dem {

struct Particles;

struct LammpsData {
  Eigen::Vector3d box_lo = Eigen::Vector3d::Zero();
  Eigen::Vector3d box_hi = Eigen::Vector3d::Zero();
  std::vector<std::int64_t> id;
  std::vector<int> type;
  std::vector<double> diameter;
  std::vector<double> density;
  std::vector<Eigen::Vector3d> position;
  std::vector<Eigen::Vector3d> velocity;          ///< zero without a Velocities section
  std::vector<Eigen::Vector3d> angular_velocity;  ///< zero without a Velocities section

  std::size_t size() const { return id.size(); }
  /// Throws Error (with file and line) on a missing file, malformed line or atom count mismatch.
  static LammpsData read(const std::string& path);

  /// The particles as a data set: ids, type = material id + 1, diameter 2 R, the density of each
  /// particle's material (material_density[material id]) where its mass is the one that density
  /// gives (m = rho 4/3 pi R^3, as System::add_particle() computes it), else m / (4/3 pi R^3)
  /// (fragments that carry restored mass); positions, velocities, angular velocities. The box
  /// is the particles' bounding box.
  static LammpsData of(const Particles& particles, const std::vector<double>& material_density);

  /// Writes the format read() reads (Atoms and Velocities sections) with every number in its
  /// shortest exact decimal form (std::to_chars), so that read() gives back the same doubles bit
  /// for bit. Written to path + ".tmp" and renamed: the file is complete or absent, never
  /// truncated. Throws Error when the file cannot be written.
  void write(const std::string& path, const std::string& title) const;
};

}  // namespace partita::dem
