// The mapping files of the bad-input corpus (tests/inputs/bad/mapping_*.yaml, run through
// `partita check` by tests/app): here their mapper nodes go straight to create_mapper, which
// must fail with the message the file's first line expects, pointing into the file.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>

#include "make_mapper.hpp"

using namespace partita;
using namespace partita::coupling;
using namespace partita::coupling::test;

TEST_CASE("bad-input corpus: mapping files fail with their expected message", "[mapping]") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(PARTITA_SOURCE_DIR) / "tests" / "inputs" / "bad";
  int count = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const fs::path f = entry.path();
    if (f.filename().string().rfind("mapping_", 0) != 0 || f.extension() != ".yaml") continue;
    ++count;
    std::ifstream in(f);
    std::string first;
    std::getline(in, first);
    const std::string want = first.substr(std::string("# expect: ").size());
    const config::Node root = config::Node::load_file(f);
    const config::Node node = root["coupling"]["exchanges"][std::size_t{0}]["mapper"];
    CAPTURE(f.filename().string(), want);
    CHECK_THROWS_WITH(create_mapper(mapper_registry(), MapperContext{node, Constraint::consistent}),
                      Catch::Matchers::Contains(want) &&
                          Catch::Matchers::Contains(f.filename().string() + ":16:"));
  }
  CHECK(count >= 5);
}
