// libFuzzer harness: the Gmsh 4.1 reader. Any input ends in a mesh or in fem::Error; anything
// else (a crash, a sanitizer report, another exception, a hang) is a finding.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "partita/fem/error.hpp"
#include "partita/fem/gmsh_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    const partita::fem::Mesh mesh = partita::fem::read_gmsh(in, "fuzz.msh");
    (void)mesh.num_elements();
  } catch (const partita::fem::Error&) {
  }
  return 0;
}
