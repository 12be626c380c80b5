#pragma once
#include <cstddef>
#include <functional>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "partita/fem/element.hpp"
#include "partita/fem/surface_element.hpp"
#include "partita/fem/types.hpp"

namespace partita::fem {

// A volume mesh in the reference configuration [m] with named element regions, named node sets
// and named faces (lists of outward-oriented surface elements). Build it with make_box_mesh()
// or read_gmsh(), or by hand: add_node(), add_element(), add_face_element(), add_node_set().
class Mesh {
 public:
  // --- construction ---
  std::size_t add_node(const Vec3& x);
  void set_node(std::size_t i, const Vec3& x);
  // Returns the region index of name, creating it if needed.
  int add_region(const std::string& name);
  std::size_t add_element(ElementType type, std::span<const std::size_t> nodes, int region = 0);
  void add_face_element(const std::string& face, FaceType type, std::span<const std::size_t> nodes);
  // Replaces the set if it exists; ids are sorted and made unique.
  void add_node_set(const std::string& name, std::vector<std::size_t> nodes);
  // The set of nodes whose position satisfies pred.
  void add_node_set_where(const std::string& name, const std::function<bool(const Vec3&)>& pred);
  // Moves every element whose centroid (the mean of its nodes) satisfies pred into the region
  // `name` (created if needed); returns how many moved. (Regions of a box mesh.)
  std::size_t assign_region_where(const std::string& name,
                                  const std::function<bool(const Vec3&)>& pred);
  // Adds the face `name` of the faces that two elements share (the faces between elements, that
  // erosion of one of them exposes), each once from either side, oriented outward from its own
  // element: face_owners() gives that element, face_across() the other. regions: only the faces
  // of elements in these regions (region indices; empty: every element). Throws Error if the
  // face `name` exists. Returns the number of face elements added.
  std::size_t add_interior_faces(const std::string& name, const std::vector<int>& regions = {});
  // Drops nodes that no element uses and renumbers nodes, sets and faces.
  void remove_unused_nodes();
  // Replaces every face element by the matching local face of the volume element it lies on
  // (outward orientation, consistent edge nodes). Throws Error for a face element that is not
  // the face of any volume element.
  void orient_faces_outward();
  // Throws Error on out-of-range node indices or empty meshes.
  void validate() const;

  // --- access ---
  std::size_t num_nodes() const { return nodes_.size(); }
  const Vec3& node(std::size_t i) const { return nodes_[i]; }
  const std::vector<Vec3>& nodes() const { return nodes_; }
  std::size_t num_elements() const { return elements_.size(); }
  const Element& element(std::size_t e) const { return elements_[e]; }
  const std::vector<Element>& elements() const { return elements_; }
  const std::vector<std::string>& region_names() const { return region_names_; }
  // Index of a region; throws Error (listing the known regions) if absent.
  int region(const std::string& name) const;

  bool has_node_set(const std::string& name) const { return node_sets_.count(name) > 0; }
  // Throws Error listing the known sets if absent.
  const std::vector<std::size_t>& node_set(const std::string& name) const;
  std::vector<std::string> node_set_names() const;

  bool has_face(const std::string& name) const { return faces_.count(name) > 0; }
  // Throws Error listing the known faces if absent.
  const std::vector<SurfaceElement>& face(const std::string& name) const;
  std::vector<std::string> face_names() const;
  // Sorted unique nodes of a face.
  std::vector<std::size_t> face_nodes(const std::string& name) const;
  // The volume element each surface element of a face bounds (the first element that has its
  // corners; where two elements have them, the one the face points away from), in the face's
  // order. Throws Error for a surface element that bounds none.
  std::vector<std::size_t> face_owners(const std::string& name) const;
  // The element on the other side of each surface element of a face (the element that shares
  // its corners and is not its owner), num_elements() where there is none (the boundary).
  std::vector<std::size_t> face_across(const std::string& name) const;

 private:
  std::vector<Vec3> nodes_;
  std::vector<Element> elements_;
  std::vector<std::string> region_names_;
  std::map<std::string, std::vector<std::size_t>> node_sets_;
  std::map<std::string, std::vector<SurfaceElement>> faces_;
};

}  // namespace partita::fem
