#pragma once
// Running a shell command from a test: its exit status, whether a signal ended it, and its
// combined stdout and stderr. Header-only, shared by the tests that drive the partita executable.

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace partita::test {

struct CommandResult {
  int status = -1;         ///< exit status, -1 if the command did not exit normally
  bool signalled = false;  ///< ended by a signal (a crash)
  std::string output;      ///< stdout and stderr together
};

/// 'text' quoted for the shell.
inline std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += (c == '\'') ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

/// Run `command` through the shell with stderr joined to stdout.
inline CommandResult run_command(const std::string& command) {
  CommandResult r;
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  if (!p) {
    r.output = "popen failed";
    return r;
  }
  std::array<char, 4096> buf{};
  while (std::fgets(buf.data(), static_cast<int>(buf.size()), p)) r.output += buf.data();
  const int st = pclose(p);
  r.signalled = WIFSIGNALED(st);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

#ifdef PARTITA_EXECUTABLE
/// The partita executable of this build with `args` (already quoted where needed).
inline CommandResult run_partita(const std::string& args) {
  return run_command(quote(PARTITA_EXECUTABLE) + " " + args);
}
#endif

}  // namespace partita::test
