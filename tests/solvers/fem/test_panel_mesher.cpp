// The cellular panel of the panel mesher (a double-hull side section): every region's volume
// and every cavity cell's surface equal their analytic values, the cells' faces point into the
// cavity and enclose it (divergence theorem), the joints are conforming (no duplicate nodes,
// every interior face shared by exactly two elements, every free face in exactly one named set),
// a panel without webs is the box mesher's two plates, and bad input is refused with the rule.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "partita/fem/box_mesher.hpp"
#include "partita/fem/element_topology.hpp"
#include "partita/fem/error.hpp"
#include "partita/fem/panel_mesher.hpp"
#include "partita/fem/quadrature.hpp"
#include "partita/fem/shape_functions.hpp"

using namespace partita::fem;

namespace {

// sum over the region's elements of int det J dV (exact for the grid's affine cells)
double region_volume(const Mesh& mesh, const std::string& region) {
  const int r = mesh.region(region);
  double v = 0.0;
  ShapeVector n;
  ShapeGradient dn;
  for (const Element& el : mesh.elements()) {
    if (el.region != r) continue;
    Eigen::Matrix<double, Eigen::Dynamic, 3> x(node_count(el.type), 3);
    for (int a = 0; a < node_count(el.type); ++a) x.row(a) = mesh.node(el.nodes[a]).transpose();
    for (const auto& q : volume_rule(el.type, QuadratureUse::Mass)) {
      shape_functions(el.type, q.xi, n, dn);
      v += q.weight * (x.transpose() * dn).determinant();
    }
  }
  return v;
}

struct Surface {
  double area = 0.0;                           // [m^2]
  Vec3 area_normal = Vec3::Zero();             // int n dA [m^2]
  double x_dot_n = 0.0;                        // int x . n dA [m^3]
  std::vector<std::pair<Vec3, Vec3>> centres;  // (centre, unit normal) of each face element
};

Surface integrate(const Mesh& mesh, const std::string& face) {
  Surface s;
  FaceShapeVector n;
  FaceShapeGradient dn;
  for (const SurfaceElement& f : mesh.face(face)) {
    Eigen::Matrix<double, Eigen::Dynamic, 3> x(node_count(f.type), 3);
    for (int a = 0; a < node_count(f.type); ++a) x.row(a) = mesh.node(f.nodes[a]).transpose();
    for (const auto& q : face_rule(f.type)) {
      shape_functions(f.type, q.xi, n, dn);
      const Vec3 p = x.transpose() * n;
      const Eigen::Matrix<double, 3, 2> j = x.transpose() * dn;
      const Vec3 an = j.col(0).cross(j.col(1));  // |an| = the area scale, an / |an| = normal
      s.area += q.weight * an.norm();
      s.area_normal += q.weight * an;
      s.x_dot_n += q.weight * p.dot(an);
    }
    const Eigen::Vector2d mid = f.type == FaceType::Quad4 || f.type == FaceType::Quad8
                                    ? Eigen::Vector2d(0.0, 0.0)
                                    : Eigen::Vector2d(1.0 / 3.0, 1.0 / 3.0);
    shape_functions(f.type, mid, n, dn);
    const Eigen::Matrix<double, 3, 2> j = x.transpose() * dn;
    s.centres.emplace_back(x.transpose() * n, j.col(0).cross(j.col(1)).normalized());
  }
  return s;
}

// A panel with cells closed on every side (webs flush with the footprint's edges) and one with
// cells open at the edges; both with a crossing of a frame and a stringer.
PanelSpec closed_panel(ElementType type) {
  PanelSpec s;
  s.origin = Vec3(0.1, -0.2, 0.05);
  s.footprint_x = 0.6;
  s.footprint_y = 0.4;
  s.outer_thickness = 0.004;
  s.inner_thickness = 0.003;
  s.depth = 0.08;
  s.web_thickness = 0.005;
  s.frames = {0.0025, 0.3, 0.5975};
  s.stringers = {0.0025, 0.22, 0.3975};
  s.element_size = 0.05;
  s.element = type;
  return s;
}

PanelSpec open_panel(ElementType type) {
  PanelSpec s = closed_panel(type);
  s.frames = {0.2, 0.45};
  s.stringers = {0.15};
  s.outer_cells = 2;
  s.web_cells = 2;
  s.depth_cells = 3;
  return s;
}

// The gaps between the webs along an axis (the cavity cells' extents), from the spec's numbers.
std::vector<std::pair<double, double>> gaps(double length, std::vector<double> webs, double t) {
  std::sort(webs.begin(), webs.end());
  std::vector<std::pair<double, double>> g;
  double at = 0.0;
  for (double w : webs) {
    if (w - t / 2 > at + 1e-12) g.emplace_back(at, w - t / 2);
    at = w + t / 2;
  }
  if (length > at + 1e-12) g.emplace_back(at, length);
  return g;
}

bool flush(double v, double edge) {
  return std::abs(v - edge) < 1e-12;
}

void check_analytic(const PanelSpec& s) {
  const Mesh mesh = make_panel_mesh(s);
  const double lx = s.footprint_x, ly = s.footprint_y, h = s.depth, t = s.web_thickness;
  const double nf = static_cast<double>(s.frames.size()),
               ns = static_cast<double>(s.stringers.size());
  CHECK(region_volume(mesh, "outer_plate") == Approx(lx * ly * s.outer_thickness).epsilon(1e-12));
  CHECK(region_volume(mesh, "inner_plate") == Approx(lx * ly * s.inner_thickness).epsilon(1e-12));
  CHECK(region_volume(mesh, "webs") ==
        Approx((nf * t * ly + ns * t * lx - nf * ns * t * t) * h).epsilon(1e-12));
  // the struck face and the interior face: the whole footprint, normals -z and +z, at their planes
  const Surface outer = integrate(mesh, "outer"), inner = integrate(mesh, "inner");
  CHECK(outer.area == Approx(lx * ly).epsilon(1e-12));
  CHECK(outer.area_normal.z() == Approx(-lx * ly).epsilon(1e-12));
  CHECK(inner.area_normal.z() == Approx(lx * ly).epsilon(1e-12));
  for (const auto& [x, n] : outer.centres) CHECK(x.z() == Approx(s.origin.z()).epsilon(1e-14));
  const double z1 = s.origin.z() + s.outer_thickness, z2 = z1 + h;
  const double z3 = z2 + s.inner_thickness;
  for (const auto& [x, n] : inner.centres) CHECK(x.z() == Approx(z3).epsilon(1e-14));
  // the edge faces: the plates' ends and the webs' (a web flush with the edge: its whole side)
  const auto has = [](const std::vector<double>& webs, double at) {
    return std::any_of(webs.begin(), webs.end(), [&](double w) { return flush(w, at); });
  };
  const double x_lo =
      (s.outer_thickness + s.inner_thickness) * ly + h * (has(s.frames, 0.5 * t) ? ly : ns * t);
  const double x_hi = (s.outer_thickness + s.inner_thickness) * ly +
                      h * (has(s.frames, lx - 0.5 * t) ? ly : ns * t);
  const double y_hi = (s.outer_thickness + s.inner_thickness) * lx +
                      h * (has(s.stringers, ly - 0.5 * t) ? lx : nf * t);
  CHECK(integrate(mesh, "xmin").area_normal.x() == Approx(-x_lo).epsilon(1e-12));
  CHECK(integrate(mesh, "xmax").area == Approx(x_hi).epsilon(1e-12));
  CHECK(integrate(mesh, "ymax").area_normal.y() == Approx(y_hi).epsilon(1e-12));

  const auto gx = gaps(lx, s.frames, t), gy = gaps(ly, s.stringers, t);
  std::size_t cells = 0;
  double floors = 0.0, sides = 0.0;  // the cells' floor areas and their webs' sides
  for (std::size_t i = 0; i < gx.size(); ++i) {
    for (std::size_t j = 0; j < gy.size(); ++j) {
      const std::string name = "cell_" + std::to_string(i) + "_" + std::to_string(j);
      INFO(name);
      REQUIRE(mesh.has_face(name));
      ++cells;
      const auto [x0, x1] = gx[i];
      const auto [y0, y1] = gy[j];
      const double a = x1 - x0, b = y1 - y0;
      // floor and ceiling, and the webs' sides (a side at the footprint's edge is open)
      const int x_sides = !flush(x0, 0.0) + !flush(x1, lx);
      const int y_sides = !flush(y0, 0.0) + !flush(y1, ly);
      const Surface c = integrate(mesh, name);
      CHECK(c.area == Approx(2 * a * b + x_sides * b * h + y_sides * a * h).epsilon(1e-12));
      floors += a * b;
      sides += x_sides * b * h + y_sides * a * h;
      // every face element points into its cavity: a step along the normal from its centre
      // lands in the cell's box, a step back in the solid (outside the box)
      const Vec3 lo(s.origin.x() + x0, s.origin.y() + y0, z1);
      const Vec3 hi(s.origin.x() + x1, s.origin.y() + y1, z2);
      const double step = 1e-4;
      const auto inside = [&](const Vec3& p) {
        return (p.array() > lo.array()).all() && (p.array() < hi.array()).all();
      };
      bool into = true;
      for (const auto& [x, n] : c.centres)
        into = into && inside(x + step * n) && !inside(x - step * n);
      CHECK(into);
      if (x_sides == 2 && y_sides == 2) {
        // a closed cell: int n dA = 0 and -1/3 int x . n dA = the cavity's volume
        CHECK(c.area_normal.norm() < 1e-12 * c.area);
        CHECK(-c.x_dot_n / 3.0 == Approx(a * b * h).epsilon(1e-12));
      }
      // its node set holds its faces' nodes
      CHECK(mesh.node_set(name) == mesh.face_nodes(name));
    }
  }
  CHECK(cells == gx.size() * gy.size());
  std::size_t cell_faces = 0;
  for (const auto& f : mesh.face_names()) cell_faces += f.rfind("cell_", 0) == 0;
  CHECK(cell_faces == cells);

  // the same faces by part: the plates' faces toward the cavity (the cells' floors and ceilings,
  // at the cavity's planes, normals into it) and the webs' sides; "cavity" all of them
  const Surface outer_side = integrate(mesh, "cavity_outer"),
                inner_side = integrate(mesh, "cavity_inner"),
                web_sides = integrate(mesh, "cavity_webs"), cavity = integrate(mesh, "cavity");
  CHECK(outer_side.area == Approx(floors).epsilon(1e-12));
  CHECK(outer_side.area_normal.z() == Approx(floors).epsilon(1e-12));
  for (const auto& [x, n] : outer_side.centres) CHECK(x.z() == Approx(z1).epsilon(1e-14));
  CHECK(inner_side.area == Approx(floors).epsilon(1e-12));
  CHECK(inner_side.area_normal.z() == Approx(-floors).epsilon(1e-12));
  for (const auto& [x, n] : inner_side.centres) CHECK(x.z() == Approx(z2).epsilon(1e-14));
  if (sides > 0.0) {
    CHECK(web_sides.area == Approx(sides).epsilon(1e-12));
    for (const auto& [x, n] : web_sides.centres) CHECK(std::abs(n.z()) < 1e-14);
  }
  CHECK(cavity.area == Approx(2 * floors + sides).epsilon(1e-12));
  CHECK(mesh.face("cavity").size() == mesh.face("cavity_outer").size() +
                                          mesh.face("cavity_inner").size() +
                                          (sides > 0.0 ? mesh.face("cavity_webs").size() : 0));
}

void check_conforming(const Mesh& mesh) {
  // no two nodes at one place (the lattice's coordinates are exact: round to 1 nm)
  std::set<std::tuple<long, long, long>> places;
  for (const Vec3& x : mesh.nodes())
    places.emplace(std::lround(x.x() * 1e9), std::lround(x.y() * 1e9), std::lround(x.z() * 1e9));
  CHECK(places.size() == mesh.num_nodes());
  // every local face of every element: shared by exactly two elements, or free and then in
  // exactly one named face set
  std::map<std::vector<std::size_t>, int> count;
  for (const Element& el : mesh.elements())
    for (int f = 0; f < local_face_count(el.type); ++f) {
      std::vector<std::size_t> key;
      for (int a : local_face_nodes(el.type, f)) key.push_back(el.nodes[a]);
      std::sort(key.begin(), key.end());
      ++count[key];
    }
  // (the cavity's faces by part, "cavity*", group faces that are in their cells' sets)
  std::map<std::vector<std::size_t>, int> named;
  for (const auto& name : mesh.face_names())
    if (name.rfind("cavity", 0) != 0)
      for (const SurfaceElement& f : mesh.face(name)) {
        std::vector<std::size_t> key(f.node_span().begin(), f.node_span().end());
        std::sort(key.begin(), key.end());
        ++named[key];
      }
  std::size_t bad = 0, free_faces = 0;
  for (const auto& [key, n] : count) {
    if (n > 2) ++bad;
    if (n == 1) {
      ++free_faces;
      const auto it = named.find(key);
      if (it == named.end() || it->second != 1) ++bad;
    }
    if (n == 2 && named.count(key)) ++bad;  // an interior face in a set
  }
  CHECK(bad == 0);
  CHECK(named.size() == free_faces);
  // the cavity's faces by part: "cavity" is the cells' faces, each in one part's set
  const auto keys = [&](const std::string& name) {
    std::map<std::vector<std::size_t>, int> k;
    if (!mesh.has_face(name)) return k;
    for (const SurfaceElement& f : mesh.face(name)) {
      std::vector<std::size_t> key(f.node_span().begin(), f.node_span().end());
      std::sort(key.begin(), key.end());
      ++k[key];
    }
    return k;
  };
  std::map<std::vector<std::size_t>, int> cells, parts;
  for (const auto& name : mesh.face_names())
    if (name.rfind("cell_", 0) == 0)
      for (const auto& [key, n] : keys(name)) cells[key] += n;
  for (const char* part : {"cavity_outer", "cavity_inner", "cavity_webs"})
    for (const auto& [key, n] : keys(part)) parts[key] += n;
  CHECK(keys("cavity") == cells);
  CHECK(parts == cells);
}

}  // namespace

TEST_CASE("panel mesh: regions' volumes and cells' surfaces are the analytic ones",
          "[fem][panel]") {
  for (auto type : {ElementType::Hex8, ElementType::Hex20, ElementType::Tet4}) {
    INFO("element " << to_string(type));
    SECTION("closed cells " + std::string(to_string(type))) {
      check_analytic(closed_panel(type));
    }
    SECTION("cells open at the edges " + std::string(to_string(type))) {
      check_analytic(open_panel(type));
    }
  }
}

TEST_CASE("panel mesh: the joints are conforming", "[fem][panel]") {
  for (auto type : {ElementType::Hex8, ElementType::Hex20, ElementType::Tet10}) {
    INFO("element " << to_string(type));
    check_conforming(make_panel_mesh(closed_panel(type)));
    check_conforming(make_panel_mesh(open_panel(type)));
  }
  // a cellular structure needs its webs in one piece with the plates: every element is reached
  // from the first through shared faces (no web floats free of the plates)
  const Mesh mesh = make_panel_mesh(closed_panel(ElementType::Hex8));
  std::map<std::vector<std::size_t>, std::vector<std::size_t>> by_face;
  for (std::size_t e = 0; e < mesh.num_elements(); ++e)
    for (int f = 0; f < local_face_count(ElementType::Hex8); ++f) {
      std::vector<std::size_t> key;
      for (int a : local_face_nodes(ElementType::Hex8, f)) key.push_back(mesh.element(e).nodes[a]);
      std::sort(key.begin(), key.end());
      by_face[key].push_back(e);
    }
  std::vector<std::vector<std::size_t>> next(mesh.num_elements());
  for (const auto& [key, els] : by_face)
    if (els.size() == 2) next[els[0]].push_back(els[1]), next[els[1]].push_back(els[0]);
  std::vector<char> seen(mesh.num_elements(), 0);
  std::vector<std::size_t> stack = {0};
  seen[0] = 1;
  std::size_t reached = 1;
  while (!stack.empty()) {
    const std::size_t e = stack.back();
    stack.pop_back();
    for (std::size_t n : next[e])
      if (!seen[n]) seen[n] = 1, ++reached, stack.push_back(n);
  }
  CHECK(reached == mesh.num_elements());
}

TEST_CASE("panel mesh: without webs it is the box mesher's two plates", "[fem][panel]") {
  for (auto type : {ElementType::Hex8, ElementType::Hex20}) {
    INFO("element " << to_string(type));
    PanelSpec p = closed_panel(type);
    p.frames.clear();
    p.stringers.clear();
    p.outer_cells = 2;
    const Mesh panel = make_panel_mesh(p);
    const int nx = static_cast<int>(std::ceil(p.footprint_x / p.element_size - 1e-9));
    const int ny = static_cast<int>(std::ceil(p.footprint_y / p.element_size - 1e-9));
    const BoxSpec outer{p.origin,
                        Vec3(p.footprint_x, p.footprint_y, p.outer_thickness),
                        {nx, ny, p.outer_cells},
                        type};
    const Vec3 top = p.origin + Vec3(0, 0, p.outer_thickness + p.depth);
    const BoxSpec inner{
        top, Vec3(p.footprint_x, p.footprint_y, p.inner_thickness), {nx, ny, p.inner_cells}, type};
    const Mesh box_outer = make_box_mesh(outer), box_inner = make_box_mesh(inner);
    REQUIRE(panel.num_elements() == box_outer.num_elements() + box_inner.num_elements());
    // the panel's elements in order: the outer plate's, then the inner plate's, node by node at
    // the box meshes' places
    double worst = 0.0;
    std::size_t e = 0;
    for (const Mesh* box : {&box_outer, &box_inner}) {
      const int region = panel.region(box == &box_outer ? "outer_plate" : "inner_plate");
      for (const Element& b : box->elements()) {
        const Element& el = panel.element(e++);
        CHECK(el.region == region);
        for (int a = 0; a < node_count(type); ++a)
          worst = std::max(worst, (panel.node(el.nodes[a]) - box->node(b.nodes[a])).norm());
      }
    }
    CHECK(worst < 1e-15);
    // the struck face is the outer plate's zmin face, the interior face the inner plate's zmax
    const auto same_face = [&](const std::string& pf, const Mesh& box, const std::string& bf) {
      const auto& a = panel.face(pf);
      const auto& b = box.face(bf);
      REQUIRE(a.size() == b.size());
      double d = 0.0;
      for (std::size_t k = 0; k < a.size(); ++k)
        for (int n = 0; n < node_count(a[k].type); ++n)
          d = std::max(d, (panel.node(a[k].nodes[n]) - box.node(b[k].nodes[n])).norm());
      CHECK(d < 1e-15);
    };
    same_face("outer", box_outer, "zmin");
    same_face("inner", box_inner, "zmax");
    // the space between the plates is one cell, open on its four sides
    CHECK(integrate(panel, "cell_0_0").area ==
          Approx(2 * p.footprint_x * p.footprint_y).epsilon(1e-12));
  }
}

TEST_CASE("panel mesh: bad input is refused with the rule", "[fem][panel]") {
  const auto refused = [](PanelSpec s, const std::string& what) {
    try {
      make_panel_mesh(s);
    } catch (const Error& e) {
      INFO(e.what());
      CHECK(std::string(e.what()).find(what) != std::string::npos);
      return;
    }
    FAIL("accepted: " << what);
  };
  PanelSpec s = closed_panel(ElementType::Hex8);
  {
    PanelSpec b = s;
    b.frames = {0.001};
    refused(b, "reaches beyond the footprint");
  }
  {
    PanelSpec b = s;
    b.stringers = {0.2, 0.204};
    refused(b, "overlap");
  }
  {
    PanelSpec b = s;
    b.frames = {0.004};
    refused(b, "slivers");
  }
  {
    PanelSpec b = s;
    b.web_thickness = 0.0;
    refused(b, "web_thickness must be > 0");
  }
  {
    PanelSpec b = s;
    b.outer_thickness = -0.001;
    refused(b, "outer_thickness must be > 0");
  }
  {
    PanelSpec b = s;
    b.web_cells = 0;
    refused(b, "web_cells must be >= 1");
  }
}

TEST_CASE("panel mesh: the cells form places the webs flush with the edges", "[fem][panel]") {
  PanelSpec s = closed_panel(ElementType::Hex8);
  s.frames.clear();
  s.stringers.clear();
  place_webs_by_cells(s, 3, 2, 0.15);
  const double t = s.web_thickness;
  CHECK(s.footprint_x == Approx(3 * 0.15 + t).epsilon(1e-15));
  CHECK(s.footprint_y == Approx(2 * 0.15 + t).epsilon(1e-15));
  REQUIRE(s.frames.size() == 4);
  REQUIRE(s.stringers.size() == 3);
  for (std::size_t k = 0; k < s.frames.size(); ++k)
    CHECK(s.frames[k] == Approx(t / 2 + static_cast<double>(k) * 0.15).epsilon(1e-15));
  CHECK(s.stringers.back() == Approx(s.footprint_y - t / 2).epsilon(1e-15));
  // every cell closed (clear width spacing - t), parts' areas analytic
  for (auto type : {ElementType::Hex8, ElementType::Tet4}) {
    INFO("element " << to_string(type));
    s.element = type;
    check_analytic(s);
    check_conforming(make_panel_mesh(s));
  }
  const Mesh mesh = make_panel_mesh(s);
  const double a = 0.15 - t, h = s.depth;
  CHECK(integrate(mesh, "cavity_outer").area == Approx(6 * a * a).epsilon(1e-12));
  CHECK(integrate(mesh, "cavity_webs").area == Approx(6 * 4 * a * h).epsilon(1e-12));
  CHECK(mesh.has_face("cell_2_1"));
  CHECK_FALSE(mesh.has_face("cell_3_0"));
}

TEST_CASE("panel mesh: the double hull's section from its cells is the hand-written one",
          "[fem][panel]") {
  // cases/double_hull_impact: 3 x 3 cells of 118 mm clear (webs of 2 mm at 120 mm), 80 mm deep,
  // 2 mm plates, 20 mm elements; written by hand as a footprint and the webs' positions
  PanelSpec hand;
  hand.origin = Vec3::Zero();
  hand.footprint_x = hand.footprint_y = 0.362;
  hand.outer_thickness = hand.inner_thickness = hand.web_thickness = 0.002;
  hand.depth = 0.080;
  hand.frames = hand.stringers = {0.001, 0.121, 0.241, 0.361};
  hand.element_size = 0.020;
  PanelSpec cells = hand;
  cells.frames.clear();
  cells.stringers.clear();
  place_webs_by_cells(cells, 3, 3, 0.120);
  const Mesh a = make_panel_mesh(hand), b = make_panel_mesh(cells);
  REQUIRE(a.num_nodes() == b.num_nodes());
  REQUIRE(a.num_elements() == b.num_elements());
  bool same_nodes = true;
  for (std::size_t n = 0; n < a.num_nodes(); ++n)
    same_nodes = same_nodes && (a.node(n).array() == b.node(n).array()).all();  // to the bit
  CHECK(same_nodes);
  bool same_elements = true;
  for (std::size_t e = 0; e < a.num_elements(); ++e)
    same_elements = same_elements && a.element(e).region == b.element(e).region &&
                    a.element(e).nodes == b.element(e).nodes;
  CHECK(same_elements);
  REQUIRE(a.face_names() == b.face_names());
  for (const auto& name : a.face_names()) {
    INFO(name);
    const auto &fa = a.face(name), &fb = b.face(name);
    REQUIRE(fa.size() == fb.size());
    bool same = true;
    for (std::size_t k = 0; k < fa.size(); ++k)
      same = same && std::equal(fa[k].node_span().begin(), fa[k].node_span().end(),
                                fb[k].node_span().begin(), fb[k].node_span().end());
    CHECK(same);
  }
  CHECK(a.face_names().size() == 9 + 4 + 6);  // the cells, the cavity by part, outer ... ymax
}

TEST_CASE("panel mesh: the cells form refuses bad counts and spacings", "[fem][panel]") {
  const auto refused = [](int nx, int ny, double spacing, double t, const std::string& what) {
    PanelSpec s;
    s.web_thickness = t;
    try {
      place_webs_by_cells(s, nx, ny, spacing);
    } catch (const Error& e) {
      INFO(e.what());
      CHECK(std::string(e.what()).find(what) != std::string::npos);
      return;
    }
    FAIL("accepted: " << nx << " x " << ny << " at " << spacing);
  };
  refused(0, 3, 0.1, 0.002, "cells along x must be >= 1");
  refused(3, -1, 0.1, 0.002, "cells along y must be >= 1");
  refused(3, 3, 0.003, 0.002, "web_spacing (centre to centre) must be at least 2 web_thickness");
  refused(3, 3, std::nan(""), 0.002, "web_spacing");
  refused(3, 3, 0.1, 0.0, "web_thickness must be > 0");
}
