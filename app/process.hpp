#pragma once
// Starting programs without a shell: an argument vector, never a command line, so nothing in a
// path or name is ever interpreted (posix_spawn).

#include <sys/types.h>
#include <filesystem>
#include <string>
#include <vector>

namespace partita::app {

/// Start `args[0]` (searched in PATH) with `args`; its stdout and stderr go to `log` (appended
/// to and created if needed; empty path: stdout to /dev/null, stderr inherited). Returns the
/// process id, or -1 if it could not be started.
pid_t spawn(const std::vector<std::string>& args, const std::filesystem::path& log = {});

/// Wait for process `pid` (-1: any child); returns its pid and sets `exit_status` to the exit
/// status, or to 128 + N when signal N ended it. Returns -1 when there is no child to wait for.
pid_t wait_for(pid_t pid, int& exit_status);

/// spawn() and wait: the exit status, or -1 if it could not be started.
int run_program(const std::vector<std::string>& args, const std::filesystem::path& log = {});

/// /usr/bin/python3 where it exists (Debian's, with python3-matplotlib), else python3 from PATH.
std::string python_interpreter();

}  // namespace partita::app
