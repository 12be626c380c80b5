#include "partita/fem/element_type.hpp"

#include <algorithm>
#include <cctype>

#include "partita/fem/error.hpp"

namespace partita::fem {

int node_count(ElementType type) {
  switch (type) {
    case ElementType::Hex8:
      return 8;
    case ElementType::Hex20:
      return 20;
    case ElementType::Tet4:
      return 4;
    case ElementType::Tet10:
      return 10;
  }
  return 0;
}

int corner_count(ElementType type) {
  return (type == ElementType::Hex8 || type == ElementType::Hex20) ? 8 : 4;
}

std::string_view to_string(ElementType type) {
  switch (type) {
    case ElementType::Hex8:
      return "hex8";
    case ElementType::Hex20:
      return "hex20";
    case ElementType::Tet4:
      return "tet4";
    case ElementType::Tet10:
      return "tet10";
  }
  return "?";
}

ElementType element_type_from_string(std::string_view name) {
  std::string lower(name);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (auto t : {ElementType::Hex8, ElementType::Hex20, ElementType::Tet4, ElementType::Tet10}) {
    if (lower == to_string(t)) return t;
  }
  throw Error("unknown element type '" + std::string(name) +
              "'; allowed: hex8, hex20, tet4, tet10");
}

}  // namespace partita::fem
