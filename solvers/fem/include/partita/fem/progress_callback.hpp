#pragma once
#include <functional>
#include <string_view>

namespace partita::fem {

// Receives one line of progress text of the nonlinear solution (Newton iterations, cut-backs).
// The solver library does not log; a caller that wants the lines (the FEM adapter logs them at
// debug level) installs one with StructuralSolver::set_progress_callback(). Empty: no text is
// formatted at all.
using ProgressCallback = std::function<void(std::string_view)>;

}  // namespace partita::fem
