// Run-level services of `partita run`, driven through the executable as a user would:
//  - restart files: a run of 2N windows and a run of N windows resumed for N more write
//    byte-identical CSV and VTK files (implicit IQN-ILS, Aitken, IQN-IMVJ on the elastic tube;
//    explicit and implicit FEM/DEM on the seed-000 cases);
//  - SIGINT: the run finishes its window, flushes complete CSV files, writes a restart file and
//    exits with 130; the restart file continues the run;
//  - no shell: a post-processing script whose name holds quotes and ';' runs as one argument and
//    nothing in the name is executed;
//  - a diverging run stops with a diagnosis and a non-zero exit, with no non-finite number in
//    any CSV file.

#include <catch2/catch.hpp>

#include "../support/run_command.hpp"
#include "../support/scratch_files.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace fs = std::filesystem;
using partita::test::quote;

namespace {

const fs::path kSource = PARTITA_SOURCE_DIR;

fs::path scratch(const std::string& name) { return partita::test::scratch_dir("services", name); }

partita::test::CommandResult partita_run(const std::string& args) {
  return partita::test::run_partita(args);
}

std::string read_all(const fs::path& p) { return partita::test::read_file(p); }

std::size_t lines(const fs::path& p) {
  const std::string t = read_all(p);
  return static_cast<std::size_t>(std::count(t.begin(), t.end(), '\n'));
}

using partita::test::result_files;

void require_identical_results(const fs::path& a, const fs::path& b) {
  const auto fa = result_files(a), fb = result_files(b);
  REQUIRE(fa == fb);
  REQUIRE(fa.size() > 3);
  for (const auto& f : fa) {
    INFO("file " << f);
    CHECK(read_all(a / f) == read_all(b / f));
  }
}

// A run of 2N windows against N windows with restart files every N/2, resumed for N more.
// `output.every` is set to N windows so that both runs write frames at the same times.
void restart_round_trip(const std::string& case_file, double window, int n) {
  const fs::path one = scratch("one"), two = scratch("two");
  const std::string c = quote((kSource / case_file).string());
  const std::string every = " --set output.every=" + std::to_string(n * window);
  const std::string restart = " --set output.restart.every_windows=" + std::to_string(n / 2);
  auto end = [&](int windows) { return " --set time.end=" + std::to_string(windows * window); };
  auto r = partita_run("run " + c + end(2 * n) + every + " --output " + quote(one.string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  r = partita_run("run " + c + end(n) + every + restart + " --output " + quote(two.string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  const auto file = [&](int w) {
    std::string s = std::to_string(w);
    return two / "restart" / ("w" + std::string(12 - s.size(), '0') + s + ".bin");
  };
  REQUIRE(fs::exists(file(n)));
  REQUIRE(fs::exists(file(n / 2)));
  r = partita_run("run " + c + end(2 * n) + every + restart + " --resume " + quote(two.string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(r.output.find("resumed after window " + std::to_string(n)) != std::string::npos);
  require_identical_results(one, two);
  // keep: 2 (the default): the newest two remain
  CHECK_FALSE(fs::exists(file(n / 2)));
  CHECK(fs::exists(file(2 * n)));
  fs::remove_all(one);
  fs::remove_all(two);
}

}  // namespace

TEST_CASE("restart: 2N windows equal N windows resumed for N more, bit for bit", "[app][restart][slow]") {
  SECTION("implicit serial, IQN-ILS (tube)") {
    restart_round_trip("cases/elastic_tube_1d/iqn-ils.yaml", 0.01, 20);
  }
  SECTION("implicit serial, Aitken (tube)") {
    restart_round_trip("cases/elastic_tube_1d/aitken.yaml", 0.01, 20);
  }
  SECTION("implicit, IQN-IMVJ (tube)") {
    restart_round_trip("cases/elastic_tube_1d/iqn-imvj.yaml", 0.01, 20);
  }
  SECTION("explicit serial, FEM plate and DEM granules (seed 000, steel)") {
    restart_round_trip("cases/uniaxial_compaction/steel.yaml", 1.0e-5, 50);
  }
  SECTION("implicit serial, IQN-ILS, FEM rubber plate and DEM granules") {
    restart_round_trip("cases/uniaxial_compaction/rubber-implicit.yaml", 1.0e-5, 20);
  }
}

TEST_CASE("restart: a damaged, foreign or missing restart file is a clear error",
          "[app][restart]") {
  const fs::path dir = scratch("damaged");
  const std::string c = quote((kSource / "cases/elastic_tube_1d/iqn-ils.yaml").string());
  auto r = partita_run("run " + c + " --set time.end=0.05 --set output.restart.every_windows=5 " +
                       "--output " + quote(dir.string()));
  REQUIRE(r.status == 0);
  const fs::path file = dir / "restart" / "w000000000005.bin";
  REQUIRE(fs::exists(file));

  SECTION("the run has ended: nothing to continue") {
    r = partita_run("run " + c + " --set time.end=0.05 --resume " + quote(dir.string()));
    CHECK(r.status == 1);
    CHECK(r.output.find("nothing to continue") != std::string::npos);
  }
  SECTION("other participants") {
    r = partita_run("run " + c +
                    " --set time.end=0.1 --set participants.solid.cells=50 "
                    "--set participants.fluid.cells=50 --resume " +
                    quote(dir.string()));
    CHECK(r.status == 1);
    CHECK(r.output.find("participants or coupling differ") != std::string::npos);
  }
  SECTION("truncated") {
    const std::string bytes = read_all(file);
    std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes.substr(0, bytes.size() / 2);
    r = partita_run("run " + c + " --set time.end=0.1 --resume " + quote(dir.string()));
    CHECK(r.status == 1);
    CHECK_FALSE(r.signalled);
    CHECK(r.output.find("truncated") != std::string::npos);
  }
  SECTION("not a restart file") {
    std::ofstream(file, std::ios::binary | std::ios::trunc) << "hello";
    r = partita_run("run " + c + " --set time.end=0.1 --resume " + quote(dir.string()));
    CHECK(r.status == 1);
    CHECK(r.output.find("not a partita restart file") != std::string::npos);
  }
  SECTION("no restart folder") {
    fs::remove_all(dir / "restart");
    r = partita_run("run " + c + " --set time.end=0.1 --resume " + quote(dir.string()));
    CHECK(r.status == 1);
    CHECK(r.output.find("no restart file") != std::string::npos);
  }
  fs::remove_all(dir);
}

namespace {

// The tube (IQN-ILS) interrupted by SIGINT after about a second, then resumed; `scheme`: the
// coupling scheme (a parallel one runs its participants on threads: the signal reaches the main
// thread, the workers finish the window).
void sigint_round_trip(const std::string& scheme) {
  const fs::path dir = scratch("signal");
  const std::string case_file = (kSource / "cases/elastic_tube_1d/iqn-ils.yaml").string();
  const std::string log = (dir / "log.txt").string();
  // a long run (10^4 windows), interrupted after about a second
  std::vector<std::string> args = {PARTITA_EXECUTABLE, "run",      case_file,   "--set",
                                   "time.end=100",     "--output", dir.string(), "--set",
                                   "coupling.scheme=" + scheme};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = 0;
  REQUIRE(posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ) == 0);
  posix_spawn_file_actions_destroy(&actions);
  // wait until the run has started its windows, then interrupt it
  for (int i = 0; i < 300 && !fs::exists(dir / "coupling.csv"); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));
  REQUIRE(kill(pid, SIGINT) == 0);
  int status = 0;
  REQUIRE(waitpid(pid, &status, 0) == pid);
  INFO(read_all(log));
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 130);

  // complete CSV files with rows (the run had not reached its 2 s flush), a restart point
  const std::size_t rows = lines(dir / "coupling.csv") - 1;
  CHECK(rows >= 1);
  CHECK(lines(dir / "tube.csv") == rows + 2);  // header + t = 0 + one row per window
  const std::string text = read_all(dir / "coupling.csv");
  REQUIRE(text.back() == '\n');
  bool found = false;
  for (const auto& e : fs::directory_iterator(dir / "restart"))
    found = found || e.is_regular_file();
  CHECK(found);

  // continue for 5 more windows
  const double end = 0.01 * static_cast<double>(rows + 5);
  const auto r = partita_run("run " + quote(case_file) + " --set time.end=" + std::to_string(end) +
                             " --set coupling.scheme=" + scheme + " --resume " + quote(dir.string()));
  INFO(r.output);
  CHECK(r.status == 0);
  CHECK(lines(dir / "coupling.csv") == rows + 5 + 1);
  fs::remove_all(dir);
}

}  // namespace

TEST_CASE("SIGINT: the window ends, CSV files are complete, a restart file continues the run",
          "[app][signal]") {
  SECTION("implicit-serial") { sigint_round_trip("implicit-serial"); }
  SECTION("implicit-parallel, the participants on threads") {
    sigint_round_trip("implicit-parallel");
  }
}

TEST_CASE(
    "no shell: a script name with quotes and a semicolon is one argument and runs nothing else",
    "[app][security]") {
  const fs::path dir = scratch("shell");
  const std::string script = "post'; touch pwned; echo '.py";
  std::ofstream(dir / script) << "import sys, pathlib\n"
                                 "pathlib.Path(sys.argv[1], 'script_ran').write_text('yes')\n";
  std::string yaml = read_all(kSource / "cases/elastic_tube_1d/iqn-ils.yaml");
  yaml += "\n";
  const auto at = yaml.find("output: {every: 0.1}");
  REQUIRE(at != std::string::npos);
  yaml.replace(at, std::string("output: {every: 0.1}").size(),
               "output: {every: 0.1, scripts: [\"post'; touch pwned; echo '.py\"]}");
  std::ofstream(dir / "case.yaml") << yaml;
  const fs::path out = dir / "out";
  const auto r =
      partita::test::run_command("cd " + quote(dir.string()) + " && " + quote(PARTITA_EXECUTABLE) +
                                 " run case.yaml " + "--set time.end=0.02 --output out");
  INFO(r.output);
  CHECK(r.status == 0);
  CHECK(fs::exists(out / "script_ran"));
  CHECK_FALSE(fs::exists(dir / "pwned"));
  CHECK_FALSE(fs::exists(out / "pwned"));
  fs::remove_all(dir);
}

TEST_CASE("a diverging run stops with a diagnosis, non-zero, with finite numbers in its files",
          "[app][divergence]") {
  // The seed-000 steel plate loaded with 100 MPa instead of 10 kPa: the granules cannot hold it
  // and the plate runs away through them. The FE check (a node moved more than the model's
  // size) must stop the run within a few windows.
  const fs::path dir = scratch("diverge");
  const auto r = partita_run(
      "run " + quote((kSource / "cases/uniaxial_compaction/steel.yaml").string()) +
      " --set time.end=0.01 --set \"participants.plate.loads[0].pressure=100 MPa\" --output " +
      quote(dir.string()));
  INFO(r.output);
  CHECK(r.status == 1);
  CHECK_FALSE(r.signalled);
  CHECK(r.output.find("participant 'plate'") != std::string::npos);
  CHECK(r.output.find("more than the model's size") != std::string::npos);
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() != ".csv") continue;
    const std::string t = read_all(e.path());
    INFO(e.path());
    CHECK(t.find("nan") == std::string::npos);
    CHECK(t.find("inf") == std::string::npos);
    CHECK(lines(e.path()) >= 2);  // the rows before the stop are there
  }
  fs::remove_all(dir);
}

TEST_CASE("the undamped rubber plate stops at the energy audit, non-zero, with finite files",
          "[app][divergence][energy]") {
  // Seed 000's rubber plate without its Rayleigh damping: the explicit coupling (the plate sees
  // the granules' traction one window late) feeds the soft plate's mesh-scale modes, the contact
  // forces grow to many times the load, and both sides receive positive work through the
  // interface: energy that the coupling creates (a lossless interface creates none). Nothing is
  // non-finite, no particle is lost and the plate stays within its size, so only the energy
  // audit can see it.
  const fs::path dir = scratch("energy");
  const auto r = partita_run(
      "run " + quote((kSource / "cases/uniaxial_compaction/rubber.yaml").string()) +
      " --set time.end=0.006 --set participants.plate.analysis.rayleigh.beta=0 --set "
      "output.scripts=[] --output " +
      quote(dir.string()));
  INFO(r.output);
  CHECK(r.status == 1);
  CHECK_FALSE(r.signalled);
  CHECK(r.output.find("the coupling between 'granules' and 'plate' has created") !=
        std::string::npos);
  CHECK(r.output.find("coupling.energy_tolerance") != std::string::npos);
  const std::string c = read_all(dir / "coupling.csv");
  CHECK(c.find("energy created granules-plate [J]") != std::string::npos);
  CHECK(c.find("nan") == std::string::npos);
  CHECK(lines(dir / "coupling.csv") >= 21);
  // the same plate with its damping passes the audit over the same windows
  const auto ok = partita_run(
      "run " + quote((kSource / "cases/uniaxial_compaction/rubber.yaml").string()) +
      " --set time.end=0.006 --set output.scripts=[] --output " + quote((dir / "damped").string()));
  INFO(ok.output);
  CHECK(ok.status == 0);
  fs::remove_all(dir);
}

TEST_CASE("a fixed substep count that breakage makes too coarse stops naming the key",
          "[app][divergence]") {
  // The confined compression with crushing: at time_step_fraction 0.2 (the case's default is
  // 0.1, chosen from its restitution) 6 DEM substeps per window are stable for the initial
  // granules (time step 1.9e-6 s, window 1e-5 s); the fragments of the first breakage (at about
  // 21.5 ms) need smaller steps, and the run must stop before the next window.
  const fs::path dir = scratch("substeps");
  const auto r = partita_run(
      "run " + quote((kSource / "cases/confined_compression/confined_compression.yaml").string()) +
      " --no-sweep --set time.end=0.03 --set coupling.substeps.granules=6"
      " --set participants.granules.time_step_fraction=0.2 --output " +
      quote(dir.string()));
  INFO(r.output);
  CHECK(r.status == 1);
  CHECK_FALSE(r.signalled);
  CHECK(r.output.find("coupling.substeps.granules = 6") != std::string::npos);
  CHECK(r.output.find("or {granules: auto}") != std::string::npos);
  fs::remove_all(dir);
}
