#pragma once
// VTK XML PolyData (.vtp) files written with the standard library only (ASCII). Files are
// written to "<path>.tmp" and renamed, so an interrupted run never leaves a truncated file.

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace partita::dem {

/// One named data array: components values per point (or cell), point after point.
struct VtkArray {
  std::string name;
  int components = 1;
  bool integer = false;  ///< written as Int64
  std::vector<double> values;
};

class VtkWriter {
 public:
  /// Points as vertices (particles). Throws Error if the file cannot be written.
  static void write_points(const std::string& path, const std::vector<Eigen::Vector3d>& points,
                           const std::vector<VtkArray>& point_data);
  /// A triangle surface with point and cell (triangle) data.
  static void write_triangles(const std::string& path, const std::vector<Eigen::Vector3d>& points,
                              const std::vector<std::array<int, 3>>& triangles,
                              const std::vector<VtkArray>& point_data,
                              const std::vector<VtkArray>& cell_data);
};

}  // namespace partita::dem
