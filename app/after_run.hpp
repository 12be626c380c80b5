#pragma once
// What a front end does after a run of the run library (partita::run::CaseRun): the PNG plots of
// the output folder's CSV files and the case's post-processing scripts. Shared by the `partita`
// executable and the Python module, so that both leave the same files in a run's folder.

#include <filesystem>
#include <string>
#include <vector>

namespace partita::app {

/// Whether a run draws the PNG plots of its CSV files: not when `no_plots_option` (--no-plots),
/// nor with PARTITA_NO_PLOTS=1 (1, true, yes, on) in the environment; 0, false, no, off or empty
/// draw them. An unknown value warns and draws them, as PARTITA_LOG_LEVEL does.
bool plots_wanted(bool no_plots_option);

/// A PNG of each CSV file of `dir` (one panel per unit), drawn by the bundled matplotlib script
/// (plot_monitors.py). A missing python3 or matplotlib costs the plots only (a warning).
void plot_csv_files(const std::filesystem::path& dir);

/// The case's post-processing scripts (output.scripts), each run by python3 with the output
/// folder as its argument; a failing script warns.
void run_scripts(const std::vector<std::filesystem::path>& scripts,
                 const std::filesystem::path& dir);

/// A bundled script of the executable (plot_monitors.py, plot_sweep.py): the source tree's when
/// this build's sources are there, else the installed one (share/partita/ of the prefix).
std::filesystem::path bundled_script(const std::string& name);

}  // namespace partita::app
