#include <catch2/catch.hpp>

#include <functional>

#include "partita/interface/registry.hpp"

TEST_CASE("registry: lookup, duplicates and 'did you mean'", "[interface][registry]") {
  partita::Registry<std::function<int()>> r("scheme");
  r.add("explicit-serial", "Algorithm 1", [] { return 1; });
  r.add("implicit-serial", "iterated", [] { return 2; });
  CHECK(r.get("implicit-serial").factory() == 2);
  CHECK(r.names() == std::vector<std::string>{"explicit-serial", "implicit-serial"});
  CHECK_THROWS_WITH(r.add("explicit-serial", "again", [] { return 3; }),
                    Catch::Contains("registered twice"));
  CHECK_THROWS_WITH(r.get("explicit-seriel"),
                    Catch::Contains("unknown scheme 'explicit-seriel'") &&
                        Catch::Contains("explicit-serial, implicit-serial") &&
                        Catch::Contains("did you mean 'explicit-serial'?"));
  // Nothing close: no suggestion, but the known names are listed.
  try {
    r.get("monolithic");
    FAIL("no throw");
  } catch (const partita::Error& e) {
    CHECK(std::string(e.what()).find("did you mean") == std::string::npos);
    CHECK(std::string(e.what()).find("known schemes") != std::string::npos);
  }
}

TEST_CASE("edit distance", "[interface][registry]") {
  CHECK(partita::edit_distance("kitten", "sitting") == 3);
  CHECK(partita::edit_distance("", "abc") == 3);
  CHECK(partita::nearest_name("aitkin", {"constant", "aitken", "iqn-ils"}) == "aitken");
  CHECK(partita::nearest_name("xyz", {"constant", "aitken"}).empty());
}

TEST_CASE("registry: documented quantity families match their members only", "[interface]") {
  using partita::QuantityDoc;
  using partita::quantity_matches;
  const QuantityDoc mesh{"<mesh>.force_z", "N", ""}, face{"<wall>.<face>.force_z", "N", ""},
      particle{"particle.<id>.z", "m", ""}, plain{"kinetic_energy", "J", ""};
  CHECK(quantity_matches(mesh, "plate.force_z"));
  CHECK_FALSE(quantity_matches(mesh, ".force_z"));
  CHECK_FALSE(quantity_matches(mesh, "box.zmin.force_z"));  // one part, not two
  CHECK_FALSE(quantity_matches(mesh, "plate.force_x"));
  CHECK(quantity_matches(face, "box.zmin.force_z"));
  CHECK_FALSE(quantity_matches(face, "box.force_z"));
  CHECK_FALSE(quantity_matches(face, "box.zmin.force_zz"));
  CHECK(quantity_matches(particle, "particle.17.z"));
  CHECK_FALSE(quantity_matches(particle, "particle.17.vz"));
  CHECK_FALSE(quantity_matches(particle, "particle..z"));
  CHECK_FALSE(quantity_matches(particle, "grain.17.z"));
  CHECK(quantity_matches(plain, "kinetic_energy"));
  CHECK_FALSE(quantity_matches(plain, "kinetic_energy2"));
}
