#pragma once
// Restart files: DIR/restart/w<window>.bin, the complete state of a run after a window, so that
// `partita run CASE --resume DIR` continues it bit for bit. A file is the list of its sections,
// each written and read by its owner (one serialise function for both, StateArchive):
//
//   [text "partita restart file"] [u32 format] [u32 byte order 0x01020304]
//                      then the window loop's state: the case it belongs to (name, identity of
//                      its participants and coupling sections, window size), windows done,
//                      counters (the file's header, before the first section)
//   §sections          [u64 n] n x [text name]: the services' sections that follow, in order
//   §<service> ...     each service's own (service.hpp); a section no service of this run has is
//                      skipped, a service without a section in the file starts afresh or refuses
//   the scheme's       its values and its acceleration's history (CouplingScheme::serialize)
//   [u64 participants] §participant <name> and its solver's data, per participant
//   §end               then BinaryWriter's checksum table (binary_io.hpp)
//
// Format 5 (the files of earlier partita versions) kept the same values in fixed places rather
// than in the services' sections; it is still read (restart_format5.cpp).

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "partita/coupling/coupling_scheme.hpp"
#include "partita/coupling/participant.hpp"
#include "partita/run/service.hpp"

namespace partita::run {

/// The window loop's own state (in the file's header).
struct RunState {
  std::string name;            // the case
  std::uint64_t identity = 0;  // hash of its participants and coupling sections
  double window_size = 0.0;
  std::int64_t windows_done = 0;
  std::int64_t iterations = 0;           // total over the windows
  std::int64_t unconverged_windows = 0;  // accepted at max_iterations
  int max_window_iterations = 0;
  /// Window n (counted from 1) finished with report r.
  void finished(std::int64_t n, const coupling::WindowReport& r) {
    windows_done = n;
    iterations += r.iterations;
    max_window_iterations = std::max(max_window_iterations, r.iterations);
    if (!r.converged) ++unconverged_windows;
  }
  /// The case (read first and checked: a file of another case is named as such).
  void serialize_case(StateArchive& ar);
  void serialize_windows_done(StateArchive& ar);
  void serialize_counters(StateArchive& ar);
};

/// What a restart file holds, by owner.
struct RestartParts {
  RunState* run = nullptr;
  std::vector<Service*> services;  // the run's services, in their order
  coupling::CouplingScheme* scheme = nullptr;
  std::vector<coupling::Participant*> participants;
};

/// Write the restart file `path` (atomically).
void write_restart_file(const std::filesystem::path& path, const RestartParts& parts);

/// Read the restart file `path` into `parts`: its case checked against `parts.run` as it is set
/// (name, identity, window size), the participants' states read, the services' sections kept
/// aside (Service::restored() takes them once the caller accepts the file).
void read_restart_file(const std::filesystem::path& path, RestartParts& parts);

/// The newest restart file of the run in `output_dir` (throws partita::Error if none).
std::filesystem::path newest_restart_file(const std::filesystem::path& output_dir);
/// The restart files of a folder by window, oldest first.
std::vector<std::pair<std::int64_t, std::filesystem::path>> restart_files(
    const std::filesystem::path& dir);

/// Why restart files cannot be written ("": they can): each participant that cannot, with its
/// fix. `external_programs`: the external programs' descriptions by participant.
std::string restart_blocker(const std::vector<coupling::Participant*>& participants,
                            const std::map<std::string, std::string>& external_programs);

// (restart_format5.cpp) The sections of a format-5 file after its magic, version and byte order,
// up to the scheme's state.
void read_format5_sections(StateArchive& ar, RestartParts& parts);

}  // namespace partita::run
