#include "partita/fem/mesh.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <sstream>
#include <unordered_map>

#include "partita/fem/element_topology.hpp"
#include "partita/fem/error.hpp"

namespace partita::fem {
namespace {

template <class Map>
std::string known_names(const Map& m) {
  std::string s;
  for (const auto& [name, value] : m) s += (s.empty() ? "" : ", ") + name;
  return s.empty() ? "(none)" : s;
}

// Key of a face by its sorted corner nodes (3 or 4; unused slots max()).
using FaceKey = std::array<std::size_t, 4>;
struct FaceKeyHash {
  std::size_t operator()(const FaceKey& k) const {
    std::size_t h = 1469598103934665603ull;
    for (auto v : k) h = (h ^ v) * 1099511628211ull;
    return h;
  }
};
FaceKey make_key(std::span<const std::size_t> corners) {
  FaceKey k;
  k.fill(std::numeric_limits<std::size_t>::max());
  // insertion sort of at most 4 entries
  const std::size_t n = std::min<std::size_t>(corners.size(), 4);
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t j = i;
    for (; j > 0 && k[j - 1] > corners[i]; --j) k[j] = k[j - 1];
    k[j] = corners[i];
  }
  return k;
}

}  // namespace

std::size_t Mesh::add_node(const Vec3& x) {
  nodes_.push_back(x);
  return nodes_.size() - 1;
}

void Mesh::set_node(std::size_t i, const Vec3& x) {
  nodes_.at(i) = x;
}

int Mesh::add_region(const std::string& name) {
  auto it = std::find(region_names_.begin(), region_names_.end(), name);
  if (it != region_names_.end()) return static_cast<int>(it - region_names_.begin());
  region_names_.push_back(name);
  return static_cast<int>(region_names_.size()) - 1;
}

std::size_t Mesh::add_element(ElementType type, std::span<const std::size_t> nodes, int region) {
  if (static_cast<int>(nodes.size()) != node_count(type)) {
    throw Error("Mesh::add_element: a " + std::string(to_string(type)) + " element needs " +
                std::to_string(node_count(type)) + " nodes, got " + std::to_string(nodes.size()));
  }
  if (region_names_.empty()) region_names_.push_back("all");
  if (region < 0 || region >= static_cast<int>(region_names_.size())) {
    throw Error("Mesh::add_element: region index " + std::to_string(region) + " does not exist");
  }
  Element e;
  e.type = type;
  e.region = region;
  std::copy(nodes.begin(), nodes.end(), e.nodes.begin());
  elements_.push_back(e);
  return elements_.size() - 1;
}

void Mesh::add_face_element(const std::string& face, FaceType type,
                            std::span<const std::size_t> nodes) {
  if (static_cast<int>(nodes.size()) != node_count(type)) {
    throw Error("Mesh::add_face_element: a " + std::string(to_string(type)) + " face needs " +
                std::to_string(node_count(type)) + " nodes, got " + std::to_string(nodes.size()));
  }
  SurfaceElement s;
  s.type = type;
  std::copy(nodes.begin(), nodes.end(), s.nodes.begin());
  faces_[face].push_back(s);
}

void Mesh::add_node_set(const std::string& name, std::vector<std::size_t> nodes) {
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  node_sets_[name] = std::move(nodes);
}

void Mesh::add_node_set_where(const std::string& name,
                              const std::function<bool(const Vec3&)>& pred) {
  std::vector<std::size_t> ids;
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    if (pred(nodes_[i])) ids.push_back(i);
  }
  node_sets_[name] = std::move(ids);
}

void Mesh::remove_unused_nodes() {
  constexpr auto kNone = std::numeric_limits<std::size_t>::max();
  std::vector<std::size_t> map(nodes_.size(), kNone);
  for (const auto& e : elements_) {
    for (auto n : e.node_span()) map.at(n) = 0;
  }
  std::vector<Vec3> kept;
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    if (map[i] != kNone) {
      map[i] = kept.size();
      kept.push_back(nodes_[i]);
    }
  }
  nodes_ = std::move(kept);
  for (auto& e : elements_) {
    for (int a = 0; a < node_count(e.type); ++a) e.nodes[a] = map[e.nodes[a]];
  }
  for (auto& [name, set] : node_sets_) {
    std::vector<std::size_t> s;
    for (auto n : set) {
      if (n < map.size() && map[n] != kNone) s.push_back(map[n]);
    }
    std::sort(s.begin(), s.end());
    set = std::move(s);
  }
  for (auto& [name, list] : faces_) {
    for (std::size_t k = 0; k < list.size(); ++k) {
      auto& f = list[k];
      for (int a = 0; a < node_count(f.type); ++a) {
        if (f.nodes[a] >= map.size() || map[f.nodes[a]] == kNone) {
          throw Error("face '" + name + "': surface element " + std::to_string(k) +
                      " uses a node that belongs to no volume element");
        }
        f.nodes[a] = map[f.nodes[a]];
      }
    }
  }
}

void Mesh::orient_faces_outward() {
  std::unordered_map<FaceKey, std::pair<std::size_t, int>, FaceKeyHash> lookup;
  for (std::size_t e = 0; e < elements_.size(); ++e) {
    const auto& el = elements_[e];
    for (int f = 0; f < local_face_count(el.type); ++f) {
      const auto local = local_face_nodes(el.type, f);
      std::array<std::size_t, 4> corners{};
      const int nc = corner_count(local_face_type(el.type, f));
      for (int a = 0; a < nc; ++a) corners[a] = el.nodes[local[a]];
      lookup.emplace(make_key({corners.data(), static_cast<std::size_t>(nc)}),
                     std::make_pair(e, f));
    }
  }
  for (auto& [name, list] : faces_) {
    for (std::size_t k = 0; k < list.size(); ++k) {
      auto& s = list[k];
      const auto it = lookup.find(make_key(s.node_span().first(corner_count(s.type))));
      if (it == lookup.end()) {
        std::ostringstream msg;
        msg << "face '" << name << "': surface element " << k << " (" << to_string(s.type)
            << ", nodes";
        for (auto n : s.node_span()) msg << ' ' << n;
        msg << ") is not a face of any volume element";
        throw Error(msg.str());
      }
      const auto& el = elements_[it->second.first];
      const FaceType ft = local_face_type(el.type, it->second.second);
      if (ft != s.type) {
        throw Error("face '" + name + "': surface element " + std::to_string(k) + " is a " +
                    std::string(to_string(s.type)) + " but the volume element under it is a " +
                    std::string(to_string(el.type)) + " whose faces are " +
                    std::string(to_string(ft)) + " (mesh orders must match)");
      }
      const auto local = local_face_nodes(el.type, it->second.second);
      for (std::size_t a = 0; a < local.size(); ++a) s.nodes[a] = el.nodes[local[a]];
    }
  }
}

void Mesh::validate() const {
  if (nodes_.empty() || elements_.empty()) throw Error("mesh has no nodes or no elements");
  for (std::size_t e = 0; e < elements_.size(); ++e) {
    for (auto n : elements_[e].node_span()) {
      if (n >= nodes_.size()) {
        throw Error("element " + std::to_string(e) + " refers to node " + std::to_string(n) +
                    " but the mesh has " + std::to_string(nodes_.size()) + " nodes");
      }
    }
  }
  for (const auto& [name, set] : node_sets_) {
    for (auto n : set) {
      if (n >= nodes_.size())
        throw Error("node set '" + name + "' refers to missing node " + std::to_string(n));
    }
  }
  for (const auto& [name, list] : faces_) {
    for (const auto& s : list) {
      for (auto n : s.node_span()) {
        if (n >= nodes_.size())
          throw Error("face '" + name + "' refers to missing node " + std::to_string(n));
      }
    }
  }
}

std::size_t Mesh::assign_region_where(const std::string& name,
                                      const std::function<bool(const Vec3&)>& pred) {
  if (region_names_.empty()) region_names_.push_back("all");
  const int r = add_region(name);
  std::size_t moved = 0;
  for (auto& e : elements_) {
    Vec3 c = Vec3::Zero();
    for (auto n : e.node_span()) c += nodes_[n];
    if (pred(c / static_cast<double>(e.node_span().size()))) {
      e.region = r;
      ++moved;
    }
  }
  return moved;
}

int Mesh::region(const std::string& name) const {
  auto it = std::find(region_names_.begin(), region_names_.end(), name);
  if (it == region_names_.end()) {
    std::string known;
    for (const auto& r : region_names_) known += (known.empty() ? "" : ", ") + r;
    throw Error("unknown element region '" + name + "'; known regions: " + known);
  }
  return static_cast<int>(it - region_names_.begin());
}

const std::vector<std::size_t>& Mesh::node_set(const std::string& name) const {
  auto it = node_sets_.find(name);
  if (it == node_sets_.end()) {
    throw Error("unknown node set '" + name + "'; known node sets: " + known_names(node_sets_));
  }
  return it->second;
}

std::vector<std::string> Mesh::node_set_names() const {
  std::vector<std::string> names;
  for (const auto& [name, set] : node_sets_) names.push_back(name);
  return names;
}

const std::vector<SurfaceElement>& Mesh::face(const std::string& name) const {
  auto it = faces_.find(name);
  if (it == faces_.end()) {
    throw Error("unknown face '" + name + "'; known faces: " + known_names(faces_));
  }
  return it->second;
}

std::vector<std::string> Mesh::face_names() const {
  std::vector<std::string> names;
  for (const auto& [name, list] : faces_) names.push_back(name);
  return names;
}

std::vector<std::size_t> Mesh::face_nodes(const std::string& name) const {
  std::vector<std::size_t> ids;
  for (const auto& s : face(name)) {
    for (auto n : s.node_span()) ids.push_back(n);
  }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

namespace {

// For each surface element of `faces`: its owner (the element that has its corners; of two, the
// one it points away from) and the element across (the other, or elements.size()).
std::vector<std::array<std::size_t, 2>> face_sides(const std::vector<Vec3>& nodes,
                                                   const std::vector<Element>& elements,
                                                   const std::vector<SurfaceElement>& faces,
                                                   const std::string& name) {
  std::vector<std::vector<std::size_t>> node_elements(nodes.size());
  for (std::size_t e = 0; e < elements.size(); ++e)
    for (auto n : elements[e].node_span()) node_elements[n].push_back(e);
  const auto centroid = [&](std::span<const std::size_t> ids) {
    Vec3 c = Vec3::Zero();
    for (auto n : ids) c += nodes[n];
    return Vec3(c / static_cast<double>(ids.size()));
  };
  std::vector<std::array<std::size_t, 2>> sides;
  sides.reserve(faces.size());
  for (const auto& s : faces) {
    const int corners = corner_count(s.type);
    std::array<std::size_t, 2> found = {elements.size(), elements.size()};
    int count = 0;
    for (auto e : node_elements[s.nodes[0]]) {
      const auto en = elements[e].node_span();
      bool all = true;
      for (int c = 1; c < corners && all; ++c)
        all = std::find(en.begin(), en.end(), s.nodes[static_cast<std::size_t>(c)]) != en.end();
      if (all && count < 2) found[static_cast<std::size_t>(count++)] = e;
    }
    if (count == 0)
      throw Error("a face element of '" + name +
                  "' bounds no volume element (a face read from a file that is not the mesh's?)");
    if (count == 2) {  // a face between two elements: its owner is the one it points away from
      const auto& x = s.nodes;
      const Vec3 normal = corners == 3 ? Vec3((nodes[x[1]] - nodes[x[0]]).cross(nodes[x[2]] - nodes[x[0]]))
                                       : Vec3((nodes[x[2]] - nodes[x[0]]).cross(nodes[x[3]] - nodes[x[1]]));
      const Vec3 face_centre =
          centroid(std::span<const std::size_t>(x.data(), static_cast<std::size_t>(corners)));
      if (normal.dot(face_centre - centroid(elements[found[0]].node_span())) < 0.0)
        std::swap(found[0], found[1]);
    }
    sides.push_back(found);
  }
  return sides;
}

}  // namespace

std::vector<std::size_t> Mesh::face_owners(const std::string& name) const {
  const auto sides = face_sides(nodes_, elements_, face(name), name);  // face() throws if unknown
  std::vector<std::size_t> owners(sides.size());
  for (std::size_t k = 0; k < sides.size(); ++k) owners[k] = sides[k][0];
  return owners;
}

std::vector<std::size_t> Mesh::face_across(const std::string& name) const {
  const auto sides = face_sides(nodes_, elements_, face(name), name);
  std::vector<std::size_t> across(sides.size());
  for (std::size_t k = 0; k < sides.size(); ++k) across[k] = sides[k][1];
  return across;
}

std::size_t Mesh::add_interior_faces(const std::string& name, const std::vector<int>& regions) {
  if (has_face(name))
    throw Error("Mesh::add_interior_faces: the mesh has a face '" + name +
                "' already; choose another name");
  const auto wanted = [&](const Element& e) {
    return regions.empty() || std::find(regions.begin(), regions.end(), e.region) != regions.end();
  };
  // every local face of every element, keyed by its corners: a key met twice is shared
  std::unordered_map<FaceKey, int, FaceKeyHash> seen;
  for (const auto& e : elements_) {
    for (int f = 0; f < local_face_count(e.type); ++f) {
      const auto local = local_face_nodes(e.type, f);
      std::array<std::size_t, 4> corners{};
      const int nc = corner_count(local_face_type(e.type, f));
      for (int a = 0; a < nc; ++a) corners[static_cast<std::size_t>(a)] = e.nodes[local[a]];
      ++seen[make_key({corners.data(), static_cast<std::size_t>(nc)})];
    }
  }
  std::vector<SurfaceElement>& out = faces_[name];
  for (const auto& e : elements_) {
    if (!wanted(e)) continue;
    for (int f = 0; f < local_face_count(e.type); ++f) {
      const auto local = local_face_nodes(e.type, f);
      const FaceType type = local_face_type(e.type, f);
      std::array<std::size_t, 4> corners{};
      const int nc = corner_count(type);
      for (int a = 0; a < nc; ++a) corners[static_cast<std::size_t>(a)] = e.nodes[local[a]];
      if (seen.at(make_key({corners.data(), static_cast<std::size_t>(nc)})) < 2) continue;
      SurfaceElement s;
      s.type = type;
      for (std::size_t a = 0; a < local.size(); ++a) s.nodes[a] = e.nodes[local[a]];
      out.push_back(s);
    }
  }
  const std::size_t added = out.size();
  if (added == 0) faces_.erase(name);  // (no shared face: no face of that name)
  return added;
}

}  // namespace partita::fem
