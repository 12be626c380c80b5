// libFuzzer harness: the STL reader. Any input ends in a mesh (with or without orientation
// warnings) or in partita::Error; anything else (a crash, a sanitizer report, another exception,
// a hang) is a finding.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "partita/interface/error.hpp"
#include "partita/interface/stl.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    std::vector<std::string> warnings;  // (collected, not logged: no output per input)
    const partita::Mesh mesh = partita::parse_stl(bytes, "fuzz.stl", "mesh", 1.0, &warnings);
    (void)mesh.total_area();
    for (const std::string& w : warnings)
      if (w.rfind("fuzz.stl: ", 0) != 0) __builtin_trap();  // every warning names its source
  } catch (const partita::Error&) {
  }
  return 0;
}
