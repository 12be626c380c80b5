// The bad-input corpus: every file in tests/inputs/bad/ goes through `partita check`; each must
// end with a non-zero exit status, no signal (no crash), and one message that names the problem.

#include <catch2/catch.hpp>

#include "../support/run_command.hpp"

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

namespace fs = std::filesystem;

namespace {

using Result = partita::test::CommandResult;
using partita::test::quote;

Result run_partita(const std::string& args) {
  const Result r = partita::test::run_command(quote(PARTITA_EXECUTABLE) + " " + args);
  REQUIRE(r.output != "popen failed");
  return r;
}

std::map<std::string, std::string> manifest(const fs::path& dir) {
  std::map<std::string, std::string> m;
  std::ifstream in(dir / "expected.txt");
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    const auto colon = line.find(": ");
    if (colon != std::string::npos) m[line.substr(0, colon)] = line.substr(colon + 2);
  }
  return m;
}

std::string first_line_expectation(const fs::path& f) {
  std::ifstream in(f);
  std::string line;
  std::getline(in, line);
  const std::string tag = "# expect: ";
  return line.rfind(tag, 0) == 0 ? line.substr(tag.size()) : std::string();
}

}  // namespace

TEST_CASE("bad inputs: partita check exits non-zero with one clear message", "[app][bad-inputs]") {
  const fs::path dir = fs::path(PARTITA_SOURCE_DIR) / "tests" / "inputs" / "bad";
  const auto expected = manifest(dir);
  int count = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const fs::path f = entry.path();
    if (f.filename() == "expected.txt" || fs::is_directory(f)) continue;
    if (f.extension() != ".yaml" && f.extension() != ".yml" && f.extension() != ".stl") continue;
    ++count;
    std::string want = first_line_expectation(f);
    if (auto it = expected.find(f.filename().string()); it != expected.end()) want = it->second;
    const Result r = run_partita("check " + quote(f.string()));
    INFO("input: " << f.filename().string() << "\noutput:\n" << r.output);
    CHECK_FALSE(r.signalled);
    CHECK(r.status != 0);
    CHECK(r.status != -1);
    CHECK(r.output.find("partita: error: ") != std::string::npos);
    // The message names the file it is about.
    CHECK(r.output.find(f.filename().string()) != std::string::npos);
    if (!want.empty()) CHECK(r.output.find(want) != std::string::npos);
    // One message: a single error line (plus nothing that looks like a stack dump).
    CHECK(r.output.find("AddressSanitizer") == std::string::npos);
    CHECK(r.output.find("runtime error") == std::string::npos);
    // No standard-library text reaches the user ("cannot create std::vector larger than
    // max_size()", "stoul", "basic_string"): every message is the project's own.
    CHECK(r.output.find("std::") == std::string::npos);
    CHECK(r.output.find("basic_string") == std::string::npos);
    CHECK(r.output.find("internal error") == std::string::npos);
  }
  CHECK(count >= 25);
}

TEST_CASE("cli: version, help, usage errors", "[app][cli]") {
  const Result v = run_partita("--version");
  CHECK(v.status == 0);
  CHECK(v.output.find("partita 0.") != std::string::npos);
  const Result h = run_partita("--help");
  CHECK(h.status == 0);
  CHECK(h.output.find("run") != std::string::npos);
  CHECK(h.output.find("check") != std::string::npos);
  const Result none = run_partita("");
  CHECK(none.status != 0);
  CHECK_FALSE(none.signalled);
  const Result bad = run_partita("frobnicate");
  CHECK(bad.status != 0);
  const Result missing = run_partita("check /nonexistent/case.yaml");
  CHECK(missing.status == 1);
  CHECK(missing.output.find("no such file") != std::string::npos);
  const Result lvl = run_partita("list --log-level chatty");
  CHECK(lvl.status != 0);
}

TEST_CASE("cli: list shows every registry", "[app][cli]") {
  const Result l = run_partita("list");
  REQUIRE(l.status == 0);
  for (const char* heading :
       {"solvers:", "mappers:", "schemes:", "accelerations:", "convergence measures:"})
    CHECK(l.output.find(heading) != std::string::npos);
  CHECK(l.output.find("nearest-neighbor") != std::string::npos);
  const Result d = run_partita("docs nearest-neighbr");
  CHECK(d.status == 1);
  CHECK(d.output.find("did you mean 'nearest-neighbor'") != std::string::npos);
}

TEST_CASE("cli: --set changes a case value, and a bad one is reported at the command line",
          "[app][cli]") {
  const std::string c =
      quote(std::string(PARTITA_SOURCE_DIR) + "/cases/uniaxial_compaction/steel.yaml");
  const Result ok = run_partita(
      "check " + c + " --log-level warn --set 'participants.plate.loads[0].pressure=20 kPa'");
  CHECK(ok.status == 0);
  const Result bad = run_partita("check " + c + " --set time.window=-1");
  CHECK(bad.status == 1);
  CHECK(bad.output.find("command line (--set time.window=...)") != std::string::npos);
  CHECK(bad.output.find("0 < value") != std::string::npos);
  const Result path = run_partita("check " + c + " --set 'participants.plate.loads[7].pressure=1'");
  CHECK(path.status == 1);
  CHECK(path.output.find("has no element [7] (it has 2)") != std::string::npos);
}
