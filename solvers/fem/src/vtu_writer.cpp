#include "partita/fem/vtu_writer.hpp"

#include <charconv>
#include <cstdio>
#include <fstream>
#include <iomanip>

#include "partita/fem/error.hpp"

namespace partita::fem {
namespace {

int vtk_cell_type(ElementType type) {
  switch (type) {
    case ElementType::Hex8:
      return 12;  // VTK_HEXAHEDRON
    case ElementType::Hex20:
      return 25;  // VTK_QUADRATIC_HEXAHEDRON
    case ElementType::Tet4:
      return 10;  // VTK_TETRA
    case ElementType::Tet10:
      return 24;  // VTK_QUADRATIC_TETRA
  }
  return 0;
}

// A double as text with `digits` significant digits (std::to_chars: several times faster than
// an ostream's formatting, which dominated the output time).
void put_number(std::ostream& out, double v, int digits) {
  char buf[40];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, digits);
  out.write(buf, r.ptr - buf);
}

void write_array(std::ostream& out, const char* name, int components, const double* data,
                 std::size_t count) {
  out << "        <DataArray type=\"Float64\" Name=\"" << name << "\" NumberOfComponents=\""
      << components << "\" format=\"ascii\">\n";
  for (std::size_t i = 0; i < count; ++i) {
    out << (i % static_cast<std::size_t>(components) == 0 ? "          " : " ");
    put_number(out, data[i], 10);
    if ((i + 1) % static_cast<std::size_t>(components) == 0) out << '\n';
  }
  out << "        </DataArray>\n";
}

}  // namespace

void write_vtu(const std::string& path, const StructuralSolver& solver) {
  const Mesh& mesh = solver.mesh();
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    if (!out) throw Error(tmp + ": cannot open for writing");
    out << std::setprecision(10);
    out << "<?xml version=\"1.0\"?>\n"
        << "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
        << "  <UnstructuredGrid>\n"
        << "    <Piece NumberOfPoints=\"" << mesh.num_nodes() << "\" NumberOfCells=\""
        << mesh.num_elements() << "\">\n"
        << "      <Points>\n";
    std::vector<double> xyz;
    for (const auto& x : mesh.nodes()) xyz.insert(xyz.end(), {x[0], x[1], x[2]});
    write_array(out, "Points", 3, xyz.data(), xyz.size());
    out << "      </Points>\n      <Cells>\n"
        << "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
    for (const auto& e : mesh.elements()) {
      out << "         ";
      for (auto n : e.node_span()) out << ' ' << n;
      out << '\n';
    }
    out << "        </DataArray>\n"
        << "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    std::size_t offset = 0;
    for (const auto& e : mesh.elements()) {
      offset += static_cast<std::size_t>(node_count(e.type));
      out << "          " << offset << '\n';
    }
    out << "        </DataArray>\n"
        << "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
    for (const auto& e : mesh.elements()) out << "          " << vtk_cell_type(e.type) << '\n';
    out << "        </DataArray>\n      </Cells>\n"
        << "      <PointData Vectors=\"displacement\" Tensors=\"stress\" Scalars=\"von_mises\">\n";
    const auto n = mesh.num_nodes();
    write_array(out, "displacement", 3, solver.displacement().data(), 3 * n);
    write_array(out, "velocity", 3, solver.velocity().data(), 3 * n);
    // VTK symmetric tensors: XX YY ZZ XY YZ XZ (same as partita's Voigt order)
    const MatrixX6 s = solver.nodal_stress();
    write_array(out, "stress", 6, s.data(), 6 * n);
    const Eigen::VectorXd vm = StructuralSolver::von_mises(s);
    write_array(out, "von_mises", 1, vm.data(), n);
    out << "      </PointData>\n"
        << "      <CellData>\n"
        << "        <DataArray type=\"Int32\" Name=\"region\" format=\"ascii\">\n";
    for (const auto& e : mesh.elements()) out << "          " << e.region << '\n';
    out << "        </DataArray>\n";
    // nonlinear path: element mean of the equivalent plastic strain
    const Eigen::VectorXd eqps = solver.element_equivalent_plastic_strain();
    if (eqps.size() > 0) {
      write_array(out, "equivalent_plastic_strain", 1, eqps.data(),
                  static_cast<std::size_t>(eqps.size()));
    }
    out << "      </CellData>\n"
        << "    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
    if (!out) throw Error(tmp + ": write failed");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    throw Error("cannot rename " + tmp + " to " + path);
  }
}

}  // namespace partita::fem
