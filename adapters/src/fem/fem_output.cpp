#include "fem_output.hpp"

#include <algorithm>

namespace partita::adapters {

std::uint8_t vtk_cell_type(fem::ElementType type) {
  switch (type) {
    case fem::ElementType::Hex8:
      return 12;  // VTK_HEXAHEDRON
    case fem::ElementType::Hex20:
      return 25;  // VTK_QUADRATIC_HEXAHEDRON
    case fem::ElementType::Tet4:
      return 10;  // VTK_TETRA
    case fem::ElementType::Tet10:
      return 24;  // VTK_QUADRATIC_TETRA
  }
  return 0;
}

void write_fem_vtu(const fem::StructuralSolver& solver, const std::filesystem::path& path,
                   const vtk::Options& options,
                   std::span<const fem::IndenterContact* const> contacts) {
  static_assert(sizeof(fem::Vec3) == 3 * sizeof(double), "node arrays are xyz xyz ...");
  const fem::Mesh& mesh = solver.mesh();
  const std::size_t n = mesh.num_nodes(), ne = mesh.num_elements();
  // the cells: gathered (elements store their nodes in fixed-size arrays)
  std::vector<std::int64_t> connectivity, offsets(ne);
  std::vector<std::uint8_t> types(ne);
  std::vector<std::int32_t> region(ne);
  for (std::size_t e = 0; e < ne; ++e) {
    const fem::Element& el = mesh.elements()[e];
    for (const std::size_t v : el.node_span()) connectivity.push_back(static_cast<std::int64_t>(v));
    offsets[e] = static_cast<std::int64_t>(connectivity.size());
    types[e] = vtk_cell_type(el.type);
    region[e] = el.region;
  }
  const fem::MatrixX6 stress = solver.nodal_stress();
  const Eigen::VectorXd von_mises = fem::StructuralSolver::von_mises(stress);
  const Eigen::VectorXd eqps = solver.element_equivalent_plastic_strain();

  using vtk::DataArray;
  vtk::UnstructuredGrid piece;
  piece.points = DataArray::view("Points", n ? mesh.nodes().front().data() : nullptr, n, 3);
  piece.cells = {DataArray::view("connectivity", connectivity.data(), connectivity.size()),
                 DataArray::view("offsets", offsets.data(), ne)};
  piece.types = DataArray::view("types", types.data(), ne);
  piece.point_data = {DataArray::view("displacement", solver.displacement().data(), n, 3),
                      DataArray::view("velocity", solver.velocity().data(), n, 3),
                      DataArray::view("stress", stress.data(), n, 6),
                      DataArray::view("von_mises", von_mises.data(), n)};
  piece.point_active = {
      {"Vectors", "displacement"}, {"Tensors", "stress"}, {"Scalars", "von_mises"}};
  piece.cell_data = {DataArray::view("region", region.data(), ne)};
  std::vector<fem::Vec3> contact_force;
  if (!contacts.empty()) {
    contact_force.assign(n, fem::Vec3::Zero());
    for (const fem::IndenterContact* c : contacts)
      for (std::size_t j = 0; j < c->nodes().size(); ++j)
        contact_force[c->nodes()[j]] += c->node_forces()[j];
    piece.point_data.push_back(DataArray::view("contact_force", contact_force.front().data(), n, 3));
  }
  // equivalent plastic strain: per cell (the mean of its points) and per point (the mean of
  // the cells that share it); `failed` (1: failed, 2: eroded) with a failure criterion
  Eigen::VectorXd eqps_nodes;
  std::vector<std::int32_t> failed;
  if (eqps.size() > 0) {
    piece.cell_data.push_back(DataArray::view("equivalent_plastic_strain", eqps.data(), ne));
    eqps_nodes = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
    Eigen::VectorXd count = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
    for (std::size_t e = 0; e < ne; ++e)
      for (const std::size_t v : mesh.elements()[e].node_span()) {
        eqps_nodes[static_cast<Eigen::Index>(v)] += eqps[static_cast<Eigen::Index>(e)];
        count[static_cast<Eigen::Index>(v)] += 1.0;
      }
    eqps_nodes = eqps_nodes.cwiseQuotient(count.cwiseMax(1.0));
    piece.point_data.push_back(
        DataArray::view("equivalent_plastic_strain", eqps_nodes.data(), n));
    bool criteria = false;
    for (std::size_t r = 0; r < std::max<std::size_t>(1, mesh.region_names().size()); ++r)
      criteria = criteria || solver.model().failure_criterion(static_cast<int>(r)).active();
    if (criteria) {
      failed.resize(ne);
      for (std::size_t e = 0; e < ne; ++e)
        failed[e] = solver.element_eroded(e) ? 2 : solver.element_failed(e) ? 1 : 0;
      piece.cell_data.push_back(DataArray::view("failed", failed.data(), ne));
    }
  }
  vtk::write(path, piece, options);
}

}  // namespace partita::adapters
