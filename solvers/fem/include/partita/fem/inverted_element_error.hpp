#pragma once
#include "partita/fem/error.hpp"

namespace partita::fem {

// An element turned inside out (det F <= 0 at one of its points): the message names the element
// and where it is. The Newton solver tells it from other inadmissible trial points (a material
// law's return mapping that does not converge) to say what happened.
class InvertedElementError : public Error {
 public:
  using Error::Error;
};

}  // namespace partita::fem
