#include "partita/fem/face_type.hpp"

namespace partita::fem {

int node_count(FaceType type) {
  switch (type) {
    case FaceType::Quad4:
      return 4;
    case FaceType::Quad8:
      return 8;
    case FaceType::Tri3:
      return 3;
    case FaceType::Tri6:
      return 6;
  }
  return 0;
}

int corner_count(FaceType type) {
  return (type == FaceType::Quad4 || type == FaceType::Quad8) ? 4 : 3;
}

std::string_view to_string(FaceType type) {
  switch (type) {
    case FaceType::Quad4:
      return "quad4";
    case FaceType::Quad8:
      return "quad8";
    case FaceType::Tri3:
      return "tri3";
    case FaceType::Tri6:
      return "tri6";
  }
  return "?";
}

}  // namespace partita::fem
