// libFuzzer harness: the STL reader. Any input ends in a mesh or in partita::Error; anything else
// (a crash, a sanitizer report, another exception, a hang) is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include "partita/interface/error.hpp"
#include "partita/interface/stl.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    const partita::Mesh mesh = partita::parse_stl(bytes, "fuzz.stl", "mesh");
    (void)mesh.total_area();
  } catch (const partita::Error&) {
  }
  return 0;
}
