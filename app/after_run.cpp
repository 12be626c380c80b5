#include "after_run.hpp"

#include <algorithm>
#include <cstdlib>

#include "partita/interface/log.hpp"
#include "process.hpp"

namespace partita::app {

namespace fs = std::filesystem;

fs::path bundled_script(const std::string& name) {
  fs::path script = fs::path(PARTITA_APP_SOURCE_DIR) / name;
  if (fs::exists(script)) return script;
  // an installed executable: <prefix>/bin/partita and <prefix>/share/partita/
  std::error_code ec;
  script = fs::canonical("/proc/self/exe", ec).parent_path() / "../share/partita" / name;
  if (!ec && fs::exists(script)) return script;
  return fs::path(PARTITA_INSTALL_DATADIR) / name;  // a front end in another program (python3)
}

void plot_csv_files(const fs::path& dir) {
  std::vector<std::string> csvs;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".csv") csvs.push_back(e.path().string());
  if (csvs.empty()) return;
  std::sort(csvs.begin(), csvs.end());
  const fs::path script = bundled_script("plot_monitors.py");
  if (!fs::exists(script)) return;
  std::vector<std::string> args = {python_interpreter(), script.string()};
  args.insert(args.end(), csvs.begin(), csvs.end());
  if (run_program(args) != 0)
    log::get("app")->warn("plotting the CSV files failed (is python3-matplotlib installed?)");
  else
    log::get("app")->info("plots: {}/*.png", dir.string());
}

bool plots_wanted(bool no_plots_option) {
  if (no_plots_option) return false;
  const char* env = std::getenv("PARTITA_NO_PLOTS");
  if (env == nullptr || *env == '\0') return true;
  const std::string v = env;
  for (const char* off : {"1", "true", "yes", "on"})
    if (v == off) return false;
  for (const char* on : {"0", "false", "no", "off"})
    if (v == on) return true;
  log::get("app")->warn(
      "PARTITA_NO_PLOTS='{}' is not a switch (allowed: 1, true, yes, on: no plots; 0, false, no, "
      "off or empty: plots); drawing the plots",
      v);
  return true;
}

void run_scripts(const std::vector<fs::path>& scripts, const fs::path& dir) {
  for (const auto& s : scripts) {
    log::get("app")->info("post-processing: {}", s.filename().string());
    if (run_program({python_interpreter(), s.string(), dir.string()}) != 0)
      log::get("app")->warn("post-processing script {} failed", s.string());
  }
}

}  // namespace partita::app
