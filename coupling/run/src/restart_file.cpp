#include "restart_file.hpp"

#include <algorithm>
#include <fstream>

#include <fmt/format.h>

#include "partita/interface/binary_io.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/output.hpp"

namespace partita::run {

using namespace coupling;
namespace fs = std::filesystem;

namespace {

constexpr const char* kMagic = "partita restart file";
// 2: the energy audit; 3: section checksums; 4: the energy balance; 5: when its largest error
// occurred; 6: the services' own sections
constexpr std::uint32_t kVersion = 6;
constexpr std::uint32_t kOldestVersion = 5;  // still read (restart_format5.cpp)
constexpr std::uint32_t kByteOrder = 0x01020304u;

// DIR/restart/w000000001234.bin -> 1234; -1 for other names.
std::int64_t window_of(const fs::path& p) {
  const std::string n = p.filename().string();
  if (n.size() != 17 || n[0] != 'w' || p.extension() != ".bin") return -1;
  std::int64_t w = 0;
  for (std::size_t i = 1; i < 13; ++i) {
    if (n[i] < '0' || n[i] > '9') return -1;
    w = 10 * w + (n[i] - '0');
  }
  return w;
}

std::string versions_read() {
  return fmt::format("this partita reads versions {} to {} (resume with the partita that wrote it)",
                     kOldestVersion, kVersion);
}

std::vector<Service*> with_sections(const std::vector<Service*>& services) {
  std::vector<Service*> s;
  for (Service* x : services)
    if (!x->section().empty()) s.push_back(x);
  return s;
}

}  // namespace

void RunState::serialize_case(StateArchive& ar) {
  ar.io(name);
  ar.io(identity);
  ar.io(window_size);
}

void RunState::serialize_windows_done(StateArchive& ar) {
  ar.io(windows_done);
  if (ar.reading() && windows_done < 0) ar.fail("a window count");
}

void RunState::serialize_counters(StateArchive& ar) {
  ar.io(iterations);
  ar.io(unconverged_windows);
  ar.io(max_window_iterations);
}

std::vector<std::pair<std::int64_t, fs::path>> restart_files(const fs::path& dir) {
  std::vector<std::pair<std::int64_t, fs::path>> files;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (const std::int64_t w = window_of(e.path()); w >= 0 && e.is_regular_file())
      files.emplace_back(w, e.path());
  std::sort(files.begin(), files.end());
  return files;
}

fs::path newest_restart_file(const fs::path& output_dir) {
  const fs::path dir = output_dir / "restart";
  if (!fs::is_directory(output_dir))
    throw Error("--resume " + output_dir.string() +
                ": no such folder (give a run's output folder)");
  const auto files = restart_files(dir);
  if (files.empty())
    throw Error("--resume " + output_dir.string() + ": no restart file in " + dir.string() +
                " (a run writes them with output.restart: {every_windows: N}, at its end, or "
                "when stopped by SIGINT/SIGTERM)");
  return files.back().second;
}

std::string restart_blocker(const std::vector<Participant*>& participants,
                            const std::map<std::string, std::string>& external_programs) {
  std::string why;  // every participant that cannot, each with its fix
  for (const Participant* p : participants) {
    if (p->supports_restart()) continue;
    if (!why.empty()) why += "; ";
    if (const auto e = external_programs.find(p->name()); e != external_programs.end())
      why += fmt::format(
          "the external program {} did not call set_restart_writer() before initialize(), so it "
          "has no part to write in a restart file or to read back: in the program, call "
          "ExternalParticipant::set_restart_writer(f) before initialize() (f gives the program's "
          "state as bytes; a resumed run gives them back through restart_state()), or run "
          "without restart files",
          e->second);
    else
      why += "participant '" + p->name() + "' has a solver that cannot write restart files";
  }
  return why;
}

void write_restart_file(const fs::path& path, const RestartParts& parts) {
  AtomicFile file(path, /*binary=*/true);
  BinaryWriter out(file.stream());
  out.write(std::string(kMagic));
  out.write(kVersion);
  out.write(kByteOrder);
  StateArchive ar(out);
  parts.run->serialize_case(ar);  // the loop's state: in the file's header
  parts.run->serialize_windows_done(ar);
  parts.run->serialize_counters(ar);
  const std::vector<Service*> services = with_sections(parts.services);
  ar.section("sections");
  auto count = static_cast<std::uint64_t>(services.size());
  ar.io(count);
  for (Service* s : services) {
    const std::string name = s->section();
    ar.io(name);
  }
  for (Service* s : services) {
    ar.section(s->section());
    s->serialize(ar);
  }
  parts.scheme->serialize(ar);
  out.write(static_cast<std::uint64_t>(parts.participants.size()));
  for (Participant* p : parts.participants) {
    out.section("participant " + p->name());
    p->write_restart(out);
  }
  out.section("end");
  out.finish();  // the sections' CRC-32 table
  file.commit();
}

void read_restart_file(const fs::path& path, RestartParts& parts) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw Error("cannot read restart file " + path.string());
  BinaryReader in(file, path.string());
  std::string magic;
  try {
    in.read(magic);
  } catch (const Error&) {
  }
  if (magic != kMagic) throw Error(path.string() + " is not a partita restart file");
  // Every section against its CRC-32 before any value is used. A file of an older format has
  // no table: its version, when readable, says so more plainly than the missing table.
  try {
    in.verify_checksums();
  } catch (const Error&) {
    std::uint32_t version = 0;
    try {
      in.read(version);
    } catch (const Error&) {
    }
    if (version != 0 && version < kOldestVersion)
      throw Error(fmt::format("{} has restart format version {}; {}", path.string(), version,
                              versions_read()));
    throw;
  }
  const auto version = in.get<std::uint32_t>();
  const auto order = in.get<std::uint32_t>();
  if (order != kByteOrder)
    throw Error(path.string() + " was written on a machine of another byte order");
  if (version < kOldestVersion || version > kVersion)
    throw Error(fmt::format("{} has restart format version {}; {}", path.string(), version,
                            versions_read()));
  // the name, identity and window first: a file of another case is named as such, not as data
  // out of place
  RunState& run = *parts.run;
  const RunState expected = run;
  StateArchive ar(in);
  run.serialize_case(ar);
  if (run.name != expected.name || run.identity != expected.identity)
    throw Error(fmt::format(
        "{} was written by {} whose participants or coupling differ from this case '{}': a run "
        "resumes only with the same participants and coupling sections (time and output may "
        "change)",
        path.string(),
        run.name == expected.name ? "a version of the case" : "case '" + run.name + "'",
        expected.name));
  if (run.window_size != expected.window_size)
    throw Error(fmt::format("{} was written with time.window = {:.17g} s; this case has {:.17g} s",
                            path.string(), run.window_size, expected.window_size));

  if (version == 5) {
    read_format5_sections(ar, parts);
  } else {
    run.serialize_windows_done(ar);
    run.serialize_counters(ar);
    ar.section("sections");
    const auto count = static_cast<std::size_t>(in.get<std::uint64_t>());
    std::vector<std::string> names;
    for (std::size_t i = 0; i < count; ++i) names.push_back(in.get_string());
    for (const std::string& name : names) {
      const auto s = std::find_if(parts.services.begin(), parts.services.end(),
                                  [&](const Service* x) { return x->section() == name; });
      ar.section(name);
      if (s != parts.services.end())
        (*s)->serialize(ar);
      else  // a service this run does not have (the case's energy section was left out)
        in.raw_until([](const std::string&) { return true; });
    }
    for (Service* s : with_sections(parts.services))
      if (std::find(names.begin(), names.end(), s->section()) == names.end())
        s->without_section(path.string());
  }
  parts.scheme->serialize(ar);
  const auto participants = in.get<std::uint64_t>();
  if (participants != parts.participants.size())
    in.fail(fmt::format("{} participants (found {})", parts.participants.size(), participants));
  for (Participant* p : parts.participants) {
    in.expect_section("participant " + p->name());
    p->read_restart(in);
  }
  in.expect_section("end");
}

}  // namespace partita::run
