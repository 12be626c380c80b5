// The faces between elements (Mesh::add_interior_faces()): what erosion exposes. Counted against
// the structured box's analytic face counts, each listed once from either side, oriented away
// from its own element and toward the element across.
#include <catch2/catch.hpp>

#include <algorithm>
#include <map>
#include <set>

#include "partita/fem/box_mesher.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/panel_mesher.hpp"

using namespace partita::fem;

namespace {

Vec3 centroid(const Mesh& mesh, std::span<const std::size_t> nodes) {
  Vec3 c = Vec3::Zero();
  for (auto n : nodes) c += mesh.node(n);
  return c / static_cast<double>(nodes.size());
}

// Every face element of `name` points away from its owner and toward the element across; the
// two sides of one face name each other (both_sides: every face is there from either side; else
// a face between a region's element and another region's is there once). Returns the number of
// face elements checked.
std::size_t check_sides(const Mesh& mesh, const std::string& name, bool both_sides = true) {
  const auto& faces = mesh.face(name);
  const auto owners = mesh.face_owners(name);
  const auto across = mesh.face_across(name);
  REQUIRE(owners.size() == faces.size());
  REQUIRE(across.size() == faces.size());
  std::map<std::set<std::size_t>, std::vector<std::size_t>> by_nodes;  // corners -> face elements
  for (std::size_t k = 0; k < faces.size(); ++k) {
    const auto& s = faces[k];
    const int corners = corner_count(s.type);
    REQUIRE(across[k] < mesh.num_elements());
    REQUIRE(owners[k] != across[k]);
    const auto& x = s.nodes;
    const Vec3 normal = corners == 3 ? Vec3((mesh.node(x[1]) - mesh.node(x[0]))
                                                .cross(mesh.node(x[2]) - mesh.node(x[0])))
                                     : Vec3((mesh.node(x[2]) - mesh.node(x[0]))
                                                .cross(mesh.node(x[3]) - mesh.node(x[1])));
    const Vec3 at = centroid(mesh, {x.data(), static_cast<std::size_t>(corners)});
    CHECK(normal.dot(at - centroid(mesh, mesh.element(owners[k]).node_span())) > 0.0);
    CHECK(normal.dot(centroid(mesh, mesh.element(across[k]).node_span()) - at) > 0.0);
    by_nodes[std::set<std::size_t>(x.begin(), x.begin() + corners)].push_back(k);
  }
  for (const auto& [nodes, ks] : by_nodes) {  // each shared face twice, the sides swapped
    if (!both_sides && ks.size() == 1) continue;
    REQUIRE(ks.size() == 2);
    CHECK(owners[ks[0]] == across[ks[1]]);
    CHECK(owners[ks[1]] == across[ks[0]]);
  }
  return faces.size();
}

}  // namespace

TEST_CASE("interior faces: each face two elements share, once from either side",
          "[fem][interior]") {
  for (const ElementType type : {ElementType::Hex8, ElementType::Tet4, ElementType::Hex20}) {
    BoxSpec b;
    b.size = Vec3(0.3, 0.2, 0.1);
    b.cells = {3, 2, 2};
    b.element = type;
    Mesh mesh = make_box_mesh(b);
    const std::size_t added = mesh.add_interior_faces("between");
    // local faces = 2 shared + boundary: per cell 6 faces (hexahedra) or 6 tetrahedra of 4; on
    // the boundary 1 face per cell face (hexahedra) or 2 triangles
    const long nx = 3, ny = 2, nz = 2, cells = nx * ny * nz;
    const long boundary_cell_faces = 2 * (nx * ny + ny * nz + nx * nz);
    const bool hex = type != ElementType::Tet4;
    const long local = hex ? 6 * cells : 24 * cells;
    const long boundary = hex ? boundary_cell_faces : 2 * boundary_cell_faces;
    INFO("element type " << static_cast<int>(type));
    CHECK(static_cast<long>(added) == local - boundary);
    CHECK(check_sides(mesh, "between") == added);
    // a boundary face has no element across
    for (const auto a : mesh.face_across("zmax")) CHECK(a == mesh.num_elements());
    CHECK_THROWS_AS(mesh.add_interior_faces("zmax"), Error);  // a face of that name exists
  }
}

TEST_CASE("interior faces of a double-hull panel's regions: the webs' and the plates' joints",
          "[fem][interior][panel]") {
  PanelSpec spec;
  spec.footprint_x = 0.2;
  spec.footprint_y = 0.2;
  spec.frames = {0.1};
  spec.stringers = {0.1};
  spec.outer_thickness = 0.004;
  spec.inner_thickness = 0.004;
  spec.web_thickness = 0.004;
  spec.depth = 0.06;
  spec.element_size = 0.02;
  Mesh mesh = make_panel_mesh(spec);
  const int webs = mesh.region("webs"), inner = mesh.region("inner_plate");
  const std::size_t all = mesh.add_interior_faces("all_between");
  const std::size_t some = mesh.add_interior_faces("webs_between", {webs});
  CHECK(check_sides(mesh, "all_between") == all);
  CHECK(check_sides(mesh, "webs_between", false) == some);
  CHECK(some < all);
  // the webs' faces only; among them the faces a web shares with the inner plate (the joint a
  // granule met no face at when the web element above it eroded)
  const auto owners = mesh.face_owners("webs_between");
  const auto across = mesh.face_across("webs_between");
  std::size_t on_inner = 0;
  for (std::size_t k = 0; k < owners.size(); ++k) {
    CHECK(mesh.element(owners[k]).region == webs);
    on_inner += mesh.element(across[k]).region == inner ? 1 : 0;
  }
  CHECK(on_inner > 0);
}
