// The one Catch2 main of partita_tests.
//
// The runs the tests start (`partita run`) draw no PNG plots: PARTITA_NO_PLOTS=1 unless the
// environment says otherwise (a test that asserts a plot sets PARTITA_NO_PLOTS=0 on its command).
// The tests read the CSV files; the plots cost 2-4 s of python per short run.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include <cstdlib>

int main(int argc, char** argv) {
  ::setenv("PARTITA_NO_PLOTS", "1", 0);
  return Catch::Session().run(argc, argv);
}
