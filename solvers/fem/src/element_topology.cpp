#include "partita/fem/element_topology.hpp"

namespace partita::fem {
namespace {

constexpr std::array<std::array<int, 8>, 6> kHexFaces = {{
    {0, 3, 2, 1, 11, 10, 9, 8},
    {4, 5, 6, 7, 12, 13, 14, 15},
    {0, 1, 5, 4, 8, 17, 12, 16},
    {1, 2, 6, 5, 9, 18, 13, 17},
    {2, 3, 7, 6, 10, 19, 14, 18},
    {3, 0, 4, 7, 11, 16, 15, 19},
}};
constexpr std::array<std::array<int, 6>, 4> kTetFaces = {{
    {0, 2, 1, 6, 5, 4},
    {0, 1, 3, 4, 8, 7},
    {1, 2, 3, 5, 9, 8},
    {0, 3, 2, 7, 9, 6},
}};
constexpr std::array<std::array<int, 2>, 12> kHexEdges = {{
    {0, 1},
    {1, 2},
    {2, 3},
    {3, 0},
    {4, 5},
    {5, 6},
    {6, 7},
    {7, 4},
    {0, 4},
    {1, 5},
    {2, 6},
    {3, 7},
}};
constexpr std::array<std::array<int, 2>, 6> kTetEdges = {{
    {0, 1},
    {1, 2},
    {2, 0},
    {0, 3},
    {1, 3},
    {2, 3},
}};

}  // namespace

int local_face_count(ElementType type) {
  return (type == ElementType::Hex8 || type == ElementType::Hex20) ? 6 : 4;
}

FaceType local_face_type(ElementType type, int) {
  switch (type) {
    case ElementType::Hex8:
      return FaceType::Quad4;
    case ElementType::Hex20:
      return FaceType::Quad8;
    case ElementType::Tet4:
      return FaceType::Tri3;
    case ElementType::Tet10:
      return FaceType::Tri6;
  }
  return FaceType::Quad4;
}

std::span<const int> local_face_nodes(ElementType type, int face) {
  const auto f = static_cast<std::size_t>(face);
  const auto n = static_cast<std::size_t>(node_count(local_face_type(type, face)));
  if (type == ElementType::Hex8 || type == ElementType::Hex20) return {kHexFaces[f].data(), n};
  return {kTetFaces[f].data(), n};
}

std::span<const std::array<int, 2>> quadratic_edges(ElementType type) {
  switch (type) {
    case ElementType::Hex20:
      return {kHexEdges.data(), kHexEdges.size()};
    case ElementType::Tet10:
      return {kTetEdges.data(), kTetEdges.size()};
    default:
      return {};
  }
}

}  // namespace partita::fem
