#pragma once
#include <array>
#include <cstddef>
#include <span>

#include "partita/fem/element_type.hpp"
#include "partita/fem/types.hpp"

namespace partita::fem {

// One volume element: its type, its region (index into Mesh::region_names()) and its nodes.
struct Element {
  ElementType type = ElementType::Hex8;
  int region = 0;
  std::array<std::size_t, kMaxElementNodes> nodes{};

  std::span<const std::size_t> node_span() const {
    return {nodes.data(), static_cast<std::size_t>(node_count(type))};
  }
};

}  // namespace partita::fem
