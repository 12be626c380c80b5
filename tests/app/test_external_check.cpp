// partita check of a case with an external program (solver: external, a program that joins over
// MPI through partita::mpi::ExternalParticipant): its meshes, fields and quantities are only known
// when it joins, so the check builds the rest of the case against the exchanges that name it and
// says so; every mistake outside the program's own declarations is still found.

#include <catch2/catch.hpp>

#include "../support/run_command.hpp"

#include <filesystem>
#include <string>

namespace fs = std::filesystem;
using partita::test::quote;
using partita::test::run_partita;

namespace {

const std::string kCase =
    quote((fs::path(PARTITA_SOURCE_DIR) / "examples/external_tube/tube_external.yaml").string());

}  // namespace

TEST_CASE("external: partita check of a case with an external program checks the rest of it",
          "[app][external]") {
  const auto ok = run_partita("check " + kCase);
  INFO(ok.output);
  CHECK(ok.status == 0);
  CHECK(ok.output.find("is valid") != std::string::npos);
  CHECK(ok.output.find("participant 'solid' is an external program (solver: external): its "
                       "meshes, fields and quantities are checked when it joins the run") !=
        std::string::npos);

  // mistakes in the rest of the case: each one's own error, at its key
  const std::pair<std::string, std::string> mistakes[] = {
      {"coupling.exchanges[0].data=presure", "participant 'fluid' does not write 'presure'"},
      {"coupling.exchanges[1].to=fluid.node", "participant 'fluid' has no mesh 'node'"},
      {"coupling.exchanges[1].mapper=nearest", "unknown mapper 'nearest'"},
      {"coupling.exchanges[1].from=solids.nodes", "unknown participant 'solids'"},
      {"coupling.convergence[0].data=area", "no exchange carries data 'area'"},
      {"monitors[0].quantities[0]=fluid.inlet_presure",
       "participant 'fluid' reports no quantity 'inlet_presure'"},
  };
  for (const auto& [set, message] : mistakes) {
    const auto r = run_partita("check " + kCase + " --set " + quote(set));
    INFO(set << ": " << r.output);
    CHECK(r.status == 1);
    CHECK_FALSE(r.signalled);
    CHECK(r.output.find(message) != std::string::npos);
  }

  // running it in one process is still refused: the program joins over MPI
  const auto run = run_partita("run " + kCase + " -o " +
                               quote((fs::temp_directory_path() / "partita_external_check").string()));
  INFO(run.output);
  CHECK(run.status == 1);
  CHECK(run.output.find("is an external program (solver: external), which joins a run over MPI") !=
        std::string::npos);
}

TEST_CASE("external: partita check of a surface taken from an external program says why it "
          "cannot be checked",
          "[app][external]") {
  // the granules take the plate's bottom face as a wall; with the plate an external program, its
  // meshes are known only when it joins: not "names no participant's mesh"
  const std::string confined = quote(
      (fs::path(PARTITA_SOURCE_DIR) / "cases/confined_compression/confined_compression.yaml")
          .string());
  const auto r = run_partita("check " + confined + " --set participants.plate.solver=external");
  INFO(r.output);
  CHECK(r.status == 1);
  CHECK_FALSE(r.signalled);
  CHECK(r.output.find("names no participant's mesh") == std::string::npos);
  CHECK(r.output.find("participants.granules.meshes[0].from") != std::string::npos);  // the key
  CHECK(r.output.find("'plate.bottom' is a mesh of participant 'plate', an external program") !=
        std::string::npos);
  CHECK(r.output.find("the handshake checks this one") != std::string::npos);
  CHECK(r.output.find("cannot build participant 'granules'") != std::string::npos);
}
