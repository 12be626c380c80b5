#pragma once
#include <array>
#include <cstddef>
#include <span>

#include "partita/fem/face_type.hpp"
#include "partita/fem/types.hpp"

namespace partita::fem {

// One surface element of a named face: outward oriented, nodes are global node indices.
struct SurfaceElement {
  FaceType type = FaceType::Quad4;
  std::array<std::size_t, kMaxFaceNodes> nodes{};

  std::span<const std::size_t> node_span() const {
    return {nodes.data(), static_cast<std::size_t>(node_count(type))};
  }
};

}  // namespace partita::fem
