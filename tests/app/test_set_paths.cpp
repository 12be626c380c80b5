// `partita check CASE --set KEY.PATH=VALUE`: list elements are reached as key[i]; key.i is an
// error at the command line that points to key[i].
#include <catch2/catch.hpp>

#include <string>

#include "../support/run_command.hpp"

using partita::test::quote;

TEST_CASE("cli: --set on a list element is key[i], key.i points to key[i]", "[app][cli]") {
  const std::string exe = quote(PARTITA_EXECUTABLE);
  const std::string c =
      quote(std::string(PARTITA_SOURCE_DIR) + "/cases/uniaxial_compaction/steel.yaml");
  const auto ok = partita::test::run_command(
      exe + " check " + c +
      " --log-level warn --set 'participants.plate.loads[0].pressure=20 kPa'");
  CHECK(ok.status == 0);
  const auto dot = partita::test::run_command(
      exe + " check " + c + " --set 'participants.plate.loads.0.pressure=20 kPa'");
  INFO(dot.output);
  CHECK_FALSE(dot.signalled);
  CHECK(dot.status == 1);
  CHECK(dot.output.find("partita: error: --set 'participants.plate.loads.0.pressure=20 kPa'") !=
        std::string::npos);
  CHECK(dot.output.find("is written 'participants.plate.loads[0]'") != std::string::npos);
}
