#include "partita/adapters/dem_output.hpp"

#include <algorithm>
#include <bit>
#include <string>

#include "partita/dem/system.hpp"
#include "partita/interface/output.hpp"

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
  write_mesh_vtp(system, mesh, path, options, m.vertex_forces(), m.triangle_forces());
}

void write_mesh_vtp(const dem::System& system, int mesh, const std::filesystem::path& path,
                    const vtk::Options& options, const Eigen::MatrixX3d& vertex_forces,
                    const Eigen::MatrixX3d& triangle_forces) {
  const dem::TriangleMesh& m = system.mesh(mesh);
  vtk::PolyData piece;
  piece.points = xyz("", m.positions());
  piece.polys = vtk::Cells::uniform(m.triangles().empty() ? nullptr : m.triangles().front().data(),
                                    m.triangles().size(), 3);
  piece.point_data = {xyz("velocity", m.velocities()),
                      vtk::DataArray::rows("force", vertex_forces)};
  // active: 1 where the triangle takes part in contacts, 0 where its surface has gone (the face
  // of an eroded element, TriangleMesh::triangle_active())
  std::vector<std::uint8_t> active(m.triangles().size());
  for (std::size_t t = 0; t < active.size(); ++t)
    active[t] = m.triangle_active(static_cast<int>(t)) ? 1 : 0;
  piece.cell_data = {vtk::DataArray::rows("force", triangle_forces),
                     vtk::DataArray::own("active", std::move(active))};
  vtk::write(path, piece, options);
}

int remove_particle_pieces(const std::filesystem::path& directory, const std::string& prefix) {
  // <prefix>_particles_ then 6 digits, '_', digits, ".vtp"
  const std::string head = prefix + "_particles_";
  int removed = 0;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(directory, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() < head.size() + 6 + 2 + 4 || name.compare(0, head.size(), head) != 0 ||
        !name.ends_with(".vtp"))
      continue;
    const std::string_view rest =
        std::string_view(name).substr(head.size(), name.size() - head.size() - 4);
    const auto digits = [](std::string_view t) {
      return !t.empty() &&
             std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; });
    };
    if (rest.size() < 8 || rest[6] != '_' || !digits(rest.substr(0, 6)) || !digits(rest.substr(7)))
      continue;
    if (std::filesystem::remove(entry.path(), ec)) ++removed;
  }
  return removed;
}

void write_particles_pvtp(const std::filesystem::path& path, const std::vector<std::string>& pieces,
                          const vtk::Options& options) {
  static_assert(std::endian::native == std::endian::little, "the pieces are little endian");
  // the arrays of write_particles_vtp(), with the types it writes them in: the points and ids
  // exact, the fields Float64 or Float32 (the precision option)
  const std::string field = options.precision == vtk::Precision::float32 ? "Float32" : "Float64";
  std::string s =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"PPolyData\" version=\"1.0\" "
      "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <PPolyData GhostLevel=\"0\">\n"
      "    <PPointData>\n";
  const auto array = [&](const std::string& type, const std::string& name, int components) {
    s += "      <PDataArray type=\"" + type + "\" Name=\"" + name + "\" NumberOfComponents=\"" +
         std::to_string(components) + "\"/>\n";
  };
  array(field, "radius", 1);
  array("Int64", "id", 1);
  array(field, "velocity", 3);
  array(field, "angular_velocity", 3);
  array(field, "force", 3);
  s += "    </PPointData>\n    <PPoints>\n"
       "      <PDataArray type=\"Float64\" NumberOfComponents=\"3\"/>\n    </PPoints>\n";
  for (const std::string& piece : pieces) s += "    <Piece Source=\"" + piece + "\"/>\n";
  s += "  </PPolyData>\n</VTKFile>\n";
  write_file_atomically(path, s);
}

}  // namespace partita::adapters
