#pragma once
// Reader for the peer-benchmark bed files (LAMMPS data format, atom_style sphere):
//   header lines "N atoms", "xlo xhi" / "ylo yhi" / "zlo zhi",
//   "Atoms" section: id type diameter density x y z   (SI units; extra columns ignored)
//   optional "Velocities" section: id vx vy vz wx wy wz
// Other sections are skipped; '#' starts a comment.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace partita::dem {

struct LammpsData {
  Eigen::Vector3d box_lo = Eigen::Vector3d::Zero();
  Eigen::Vector3d box_hi = Eigen::Vector3d::Zero();
  std::vector<std::int64_t> id;
  std::vector<int> type;
  std::vector<double> diameter;
  std::vector<double> density;
  std::vector<Eigen::Vector3d> position;
  std::vector<Eigen::Vector3d> velocity;          ///< zero where no Velocities line
  std::vector<Eigen::Vector3d> angular_velocity;  ///< zero where no Velocities line

  std::size_t size() const { return id.size(); }
  /// Throws Error (with file and line) on a missing file, malformed line or atom count mismatch.
  static LammpsData read(const std::string& path);
};

}  // namespace partita::dem
