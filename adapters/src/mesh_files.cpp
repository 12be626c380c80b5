#include "partita/adapters/mesh_files.hpp"

#include <algorithm>
#include <cctype>

#include <fmt/format.h>

#include "partita/interface/error.hpp"
#include "partita/interface/stl.hpp"

#ifdef PARTITA_HAVE_FEM
#include "partita/fem/error.hpp"
#include "partita/fem/gmsh_reader.hpp"
#endif

namespace partita::adapters {

namespace {
std::string lower_extension(const std::filesystem::path& p) {
  std::string ext = p.extension().string();
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}
std::string names(const std::vector<std::string>& v) {
  return v.empty() ? std::string("none") : join_names(v);
}
}  // namespace

std::optional<std::string> describe_mesh_file(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".stl") {
    const Mesh m = read_stl(path.string(), "mesh");
    const auto box = m.bounding_box();
    return fmt::format(
        "{} is a valid STL: {} triangles, {} distinct vertices, area {:.6g} m^2 (if in metres), "
        "bounding box [{:.6g} {:.6g} {:.6g}] .. [{:.6g} {:.6g} {:.6g}]",
        path.string(), m.num_triangles(), m.size(), m.total_area(), box.min.x(), box.min.y(),
        box.min.z(), box.max.x(), box.max.y(), box.max.z());
  }
#ifdef PARTITA_HAVE_FEM
  if (ext == ".msh") {
    fem::Mesh m;
    try {
      m = fem::read_gmsh(path.string());
    } catch (const fem::Error& e) {
      throw Error(e.what());
    }
    return fmt::format(
        "{} is a valid Gmsh 4.1 mesh: {} nodes, {} volume elements; regions: {}; faces (surface "
        "physical groups): {}; node sets: {}",
        path.string(), m.num_nodes(), m.num_elements(), names(m.region_names()),
        names(m.face_names()), names(m.node_set_names()));
  }
#endif
  return std::nullopt;
}

}  // namespace partita::adapters
