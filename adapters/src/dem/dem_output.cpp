#include "partita/adapters/dem_output.hpp"

#include "partita/dem/system.hpp"

namespace partita::adapters {

namespace {
static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double), "Vector3d arrays are xyz xyz ...");
static_assert(sizeof(std::array<int, 3>) == 3 * sizeof(std::int32_t), "triangles are packed");

vtk::DataArray xyz(std::string name, const std::vector<Eigen::Vector3d>& v) {
  return vtk::DataArray::view(std::move(name), v.empty() ? nullptr : v.front().data(), v.size(), 3);
}
}  // namespace

void write_particles_vtp(const dem::System& system, const std::filesystem::path& path,
                         const vtk::Options& options) {
  write_particles_vtp(system.particles(), path, options);
}

void write_particles_vtp(const dem::Particles& p, const std::filesystem::path& path,
                         const vtk::Options& options) {
  const std::size_t n = p.size();
  vtk::PolyData piece;
  piece.points = xyz("", p.position);
  piece.verts = vtk::Cells::vertices(n);
  piece.point_data = {vtk::DataArray::view("radius", p.radius.data(), n),
                      vtk::DataArray::view("id", p.id.data(), n), xyz("velocity", p.velocity),
                      xyz("angular_velocity", p.angular_velocity), xyz("force", p.force)};
  vtk::write(path, piece, options);
}

void write_mesh_vtp(const dem::System& system, int mesh, const std::filesystem::path& path,
                    const vtk::Options& options) {
  const dem::TriangleMesh& m = system.mesh(mesh);
  vtk::PolyData piece;
  piece.points = xyz("", m.positions());
  piece.polys = vtk::Cells::uniform(m.triangles().empty() ? nullptr : m.triangles().front().data(),
                                    m.triangles().size(), 3);
  piece.point_data = {xyz("velocity", m.velocities()),
                      vtk::DataArray::rows("force", m.vertex_forces())};
  piece.cell_data = {vtk::DataArray::rows("force", m.triangle_forces())};
  vtk::write(path, piece, options);
}

}  // namespace partita::adapters
