// A refused resume changes nothing, and a damaged restart file is always refused:
//  - `partita run CASE --resume DIR` with a restart file that is empty, from another case, from
//    the same case with other participants (another particle count), of a run that has ended,
//    truncated, or with one byte flipped in any of its sections, or with other monitors (another
//    quantity, a monitor added) exits 1 with a message, and every
//    file in DIR is byte for byte what it was (no CSV rewritten with its header only, no file
//    added or removed);
//  - the checksum table at the end of a restart file (interface/binary_io.hpp documents the
//    format) is read here by an independent parser: each section is flipped in turn and named
//    in the message.

#include <catch2/catch.hpp>

#include "../support/run_command.hpp"
#include "../support/scratch_files.hpp"

#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using partita::test::quote;

namespace {

const fs::path kSource = PARTITA_SOURCE_DIR;

fs::path scratch(const std::string& name) {
  return partita::test::scratch_dir("resume", name);
}

partita::test::CommandResult partita_run(const std::string& args) {
  return partita::test::run_partita(args);
}

std::string read_all(const fs::path& p) {
  return partita::test::read_file(p);
}

void write_all(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
}

// Every regular file under `dir` (relative path -> bytes).
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files[fs::relative(e.path(), dir).string()] = read_all(e.path());
  return files;
}

void require_unchanged(const std::map<std::string, std::string>& before, const fs::path& dir) {
  const auto after = snapshot(dir);
  std::vector<std::string> names_before, names_after;
  for (const auto& [n, b] : before) names_before.push_back(n);
  for (const auto& [n, b] : after) names_after.push_back(n);
  REQUIRE(names_before == names_after);
  for (const auto& [n, b] : before) {
    INFO("file " << n);
    CHECK(after.at(n) == b);
  }
}

struct Section {
  std::string name;
  std::uint64_t offset = 0, length = 0;
};

template <class T>
T take(const std::string& bytes, std::size_t& at) {
  T v{};
  REQUIRE(at + sizeof(T) <= bytes.size());
  std::memcpy(&v, bytes.data() + at, sizeof(T));
  at += sizeof(T);
  return v;
}

// The documented layout: ... table [u64 count] (string name, u64 offset, u64 length, u32 crc)*,
// footer [u64 table offset][u32 table crc]["PRTCRC01"].
std::vector<Section> sections_of(const std::string& bytes) {
  REQUIRE(bytes.size() > 20);
  REQUIRE(bytes.substr(bytes.size() - 8) == "PRTCRC01");
  std::size_t at = bytes.size() - 20;
  const auto table = take<std::uint64_t>(bytes, at);
  at = static_cast<std::size_t>(table);
  const auto count = take<std::uint64_t>(bytes, at);
  std::vector<Section> s;
  for (std::uint64_t i = 0; i < count; ++i) {
    const auto n = take<std::uint64_t>(bytes, at);
    Section sec;
    sec.name = bytes.substr(at, static_cast<std::size_t>(n));
    at += static_cast<std::size_t>(n);
    sec.offset = take<std::uint64_t>(bytes, at);
    sec.length = take<std::uint64_t>(bytes, at);
    (void)take<std::uint32_t>(bytes, at);
    s.push_back(sec);
  }
  return s;
}

}  // namespace

TEST_CASE("resume: a refused restart file leaves every file of the run as it was",
          "[app][restart]") {
  const fs::path dir = scratch("refused"), other = scratch("other");
  const std::string c = quote((kSource / "cases/elastic_tube_1d/iqn-ils.yaml").string());
  auto r = partita_run("run " + c + " --set time.end=0.05 --set output.restart.every_windows=5 " +
                       "--output " + quote(dir.string()));
  REQUIRE(r.status == 0);
  const fs::path file = dir / "restart" / "w000000000005.bin";
  REQUIRE(fs::exists(file));
  const std::string good = read_all(file);
  // A restart file of another case (the Aitken tube: other coupling section) at the same path.
  const std::string c2 = quote((kSource / "cases/elastic_tube_1d/aitken.yaml").string());
  r = partita_run("run " + c2 + " --set time.end=0.05 --set output.restart.every_windows=5 " +
                  "--output " + quote(other.string()));
  REQUIRE(r.status == 0);
  const std::string foreign = read_all(other / "restart" / "w000000000005.bin");
  const std::string resume = "run " + c + " --set time.end=0.1 --resume " + quote(dir.string());

  struct Bad {
    const char* what;
    std::string bytes;
    std::string args;
    const char* message;
  };
  const std::vector<Bad> bad = {
      {"empty", "", resume, "not a partita restart file"},
      {"another case", foreign, resume, "whose participants or coupling differ"},
      {"other participants", good,
       "run " + c + " --set time.end=0.1 --set participants.fluid.cells=50 " +
           "--set participants.solid.cells=50 --resume " + quote(dir.string()),
       "whose participants or coupling differ"},
      {"the run has ended", good,
       "run " + c + " --set time.end=0.05 --resume " + quote(dir.string()), "nothing to continue"},
      {"truncated", good.substr(0, good.size() / 2), resume, "truncated"},
      {"cut before its checksum table", good.substr(0, good.size() - 3), resume,
       "no checksum table"},
      // the monitors are the run's: their rows so far are in the restart file
      {"a monitor with another quantity", good,
       resume + " --set \"monitors[0].quantities=[fluid.inlet_pressure, solid.mid_area]\"",
       "the monitor 'tube' asks for other quantities than in the run being resumed"},
      {"a monitor added", good,
       resume + " --set \"monitors=[{name: tube, quantities: [fluid.inlet_pressure, " +
           "fluid.outlet_pressure, fluid.inlet_velocity, solid.mid_area]}, {name: more, " +
           "quantities: [solid.mid_area]}]\"",
       "the case has 2 monitors (tube, more), the run being resumed had 1 (tube)"},
  };
  for (const Bad& b : bad) {
    SECTION(b.what) {
      write_all(file, b.bytes);
      const auto before = snapshot(dir);
      r = partita_run(b.args);
      INFO(b.what << "\n" << r.output);
      CHECK(r.status == 1);
      CHECK_FALSE(r.signalled);
      CHECK(r.output.find(b.message) != std::string::npos);
      require_unchanged(before, dir);
    }
  }
  SECTION("the good file still resumes") {
    r = partita_run(resume);
    INFO(r.output);
    CHECK(r.status == 0);
  }
  fs::remove_all(dir);
  fs::remove_all(other);
}

TEST_CASE("resume: one byte flipped in any section of a restart file is refused by name",
          "[app][restart]") {
  const fs::path dir = scratch("flipped");
  const std::string c = quote((kSource / "cases/uniaxial_compaction/steel.yaml").string());
  // the seed-000 case: FEM and DEM sections, particle positions among them
  auto r = partita_run("run " + c + " --set time.end=5.0e-5 --set output.every=1.0 " +
                       "--set output.restart.every_windows=5 --output " + quote(dir.string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  const fs::path file = dir / "restart" / "w000000000005.bin";
  REQUIRE(fs::exists(file));
  const std::string good = read_all(file);
  const auto sections = sections_of(good);
  // header, energy audit, csv, vtk, the scheme, both participants (the DEM's state among them),
  // end: every section is checked
  REQUIRE(sections.size() >= 8);
  bool dem = false;
  for (const Section& s : sections) dem = dem || s.name == "dem";
  CHECK(dem);
  const std::string resume =
      "run " + c + " --set time.end=1.0e-4 --set output.every=1.0 --resume " + quote(dir.string());
  const auto before = snapshot(dir);
  for (const Section& s : sections) {
    REQUIRE(s.length > 0);
    std::string bytes = good;
    bytes[static_cast<std::size_t>(s.offset + s.length / 2)] ^= 0x5a;
    write_all(file, bytes);
    auto expected = before;
    expected[fs::relative(file, dir).string()] = bytes;
    r = partita_run(resume);
    INFO("section '" << s.name << "'\n" << r.output);
    CHECK(r.status == 1);
    CHECK(r.output.find("section '" + s.name + "'") != std::string::npos);
    CHECK(r.output.find("is damaged") != std::string::npos);
    require_unchanged(expected, dir);
  }
  write_all(file, good);
  r = partita_run(resume);
  INFO(r.output);
  CHECK(r.status == 0);
  fs::remove_all(dir);
}

TEST_CASE("resume: a run resumed with a finer output.every writes its frames at the new spacing",
          "[app][restart]") {
  // Frames every 0.1 s to 0.5 s (restart every 5 windows of 0.01 s), resumed from 0.5 s with
  // frames every 0.02 s to 0.6 s: the series holds t = 0, 0.1 .. 0.5, then 0.52 .. 0.6 (each
  // frame once), and the run ends (the next frame time is the next multiple of the new spacing).
  const fs::path dir = scratch("finer");
  const std::string c = quote((kSource / "cases/elastic_tube_1d/iqn-ils.yaml").string());
  auto r = partita_run("run " + c + " --set time.end=0.5 --set output.restart.every_windows=5 " +
                       "--output " + quote(dir.string()));
  REQUIRE(r.status == 0);
  r = partita::test::run_command("timeout 120 " + quote(PARTITA_EXECUTABLE) + " run " + c +
                                 " --set time.end=0.6 --set output.every=0.02 --resume " +
                                 quote(dir.string()));
  INFO(r.output);
  REQUIRE(r.status == 0);
  std::vector<double> times;
  for (const auto& e : fs::directory_iterator(dir / "vtk")) {
    if (e.path().extension() != ".pvd") continue;
    const std::string pvd = read_all(e.path());
    times.clear();
    for (std::size_t at = pvd.find("timestep=\""); at != std::string::npos;
         at = pvd.find("timestep=\"", at + 1))
      times.push_back(std::stod(pvd.substr(at + 10)));
    break;
  }
  const std::vector<double> expected = {0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.52, 0.54, 0.56, 0.58, 0.6};
  REQUIRE(times.size() == expected.size());
  for (std::size_t k = 0; k < expected.size(); ++k)
    CHECK(times[k] == Approx(expected[k]).margin(1e-9));
  fs::remove_all(dir);
}
