#include "sweep_runner.hpp"

#include <algorithm>
#include <fstream>
#include <iostream>
#include <map>

#include <fmt/format.h>

#include "partita/run/case_run.hpp"
#include "partita/run/sweep.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"
#include "partita/interface/output.hpp"
#include "after_run.hpp"
#include "process.hpp"

namespace partita::app {

namespace fs = std::filesystem;

bool has_sweep(const fs::path& case_file, const std::vector<std::string>& overrides) {
  return config::Node::load_file(case_file, overrides).has("sweep");
}

namespace {

// The last line of the log that reports an error (what a failed variant's row says).
std::string error_line(const fs::path& log, int status) {
  std::ifstream in(log);
  std::string line, found;
  while (std::getline(in, line))
    if (line.find("error") != std::string::npos) found = line;
  if (found.empty()) found = "see log.txt";
  const std::string prefix = "partita: error: ";
  if (found.rfind(prefix, 0) == 0) found = found.substr(prefix.size());
  return fmt::format("failed (exit {}): {}", status, found);
}

}  // namespace

int run_sweep(const coupling::Registries& registries, const SweepOptions& options) {
  auto logger = log::get("app");
  const config::Node root = config::Node::load_file(options.case_file, options.overrides)
                                .validated(run::case_spec(registries));
  const run::Sweep sweep(root);
  {
    // What `partita check` does, before any folder is made: the case and every swept value,
    // each as its variants will run it (an error names the value's line in the case file).
    run::RunOptions check;
    check.check_only = true;
    check.overrides = options.overrides;
    check.override_origins = options.override_origins;
    check.threads = options.threads;
    const run::CaseRun checked(options.case_file, registries, check);
  }
  const fs::path dir = options.output_dir.empty() ? fs::current_path() / "out" / root.string("case")
                                                  : options.output_dir;
  fs::create_directories(dir);
  const auto& variants = sweep.variants();
  const int jobs = std::max(1, std::min<int>(options.jobs, static_cast<int>(variants.size())));
  const int threads = std::max(1, options.threads / jobs);
  logger->info("sweep of '{}': {} variants into {}/, {} at once, {} thread{} each",
               root.string("case"), variants.size(), dir.string(), jobs, threads,
               threads == 1 ? "" : "s");

  const std::string self = options.executable.empty() ? fs::canonical("/proc/self/exe").string()
                                                      : options.executable.string();
  std::vector<std::string> status(variants.size());
  std::map<pid_t, std::size_t> running;
  std::size_t next = 0, done = 0, failed = 0;
  int stopped = 0;
  auto start = [&](std::size_t k) {
    const auto& v = variants[k];
    const fs::path vdir = dir / v.folder;
    fs::create_directories(vdir);
    // the case as this variant runs it, for the record
    std::vector<std::string> all = options.overrides;
    all.insert(all.end(), v.overrides.begin(), v.overrides.end());
    {
      YAML::Emitter e;
      e << config::Node::load_file(options.case_file, all).yaml();
      write_file_atomically(vdir / "variant.yaml", std::string("# ") + v.folder + " of " +
                                                       options.case_file.string() + "\n" +
                                                       e.c_str() + "\n");
    }
    std::vector<std::string> args = {
        self,          "run",       options.case_file.string(), "--no-sweep",  "--output",
        vdir.string(), "--threads", std::to_string(threads),    "--log-level", options.log_level};
    for (const auto& o : all) {
      args.push_back("--set");
      args.push_back(o);
    }
    for (const auto& p : options.plugins) {
      args.push_back("--plugin");
      args.push_back(p);
    }
    if (!options.plots) args.push_back("--no-plots");
    std::error_code ec;
    fs::remove(vdir / "log.txt", ec);
    const pid_t pid = spawn(args, vdir / "log.txt");
    if (pid < 0) {
      status[k] = "failed: could not start " + self;
      ++done;
      ++failed;
      return;
    }
    running[pid] = k;
  };
  auto progress = [&] {
    std::cerr << fmt::format("sweep: {}/{} variants done{}, {} running\n", done, variants.size(),
                             failed ? fmt::format(" ({} failed)", failed) : std::string(),
                             running.size());
  };

  while (done < variants.size()) {
    stopped = options.stop_signal ? options.stop_signal->load() : 0;
    while (!stopped && running.size() < static_cast<std::size_t>(jobs) && next < variants.size())
      start(next++);
    if (running.empty()) break;
    int exit_status = -1;
    const pid_t pid = wait_for(-1, exit_status);
    if (pid < 0) break;
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    const std::size_t k = it->second;
    running.erase(it);
    ++done;
    if (exit_status == 0) {
      status[k] = "ok";
    } else {
      ++failed;
      status[k] = error_line(dir / variants[k].folder / "log.txt", exit_status);
      logger->warn("sweep: variant {} {}", variants[k].folder, status[k]);
    }
    progress();
  }
  for (std::size_t k = next; k < variants.size(); ++k) status[k] = "not run (stopped)";
  sweep.write_summary(dir, status);
  logger->info("sweep summary: {}", (dir / "sweep.csv").string());

  const bool plot = options.plots && !sweep.plot_monitor().empty();
  if (plot) {
    const fs::path script = bundled_script("plot_sweep.py");
    std::vector<std::string> args = {python_interpreter(),
                                     script.string(),
                                     "--x",
                                     sweep.plot_x(),
                                     "--x-scale",
                                     fmt::format("{}", sweep.plot_x_scale()),
                                     "--y-scale",
                                     fmt::format("{}", sweep.plot_y_scale()),
                                     (dir / "sweep.png").string(),
                                     sweep.plot_column()};
    for (std::size_t k = 0; k < variants.size(); ++k)
      if (status[k] == "ok") {
        args.push_back(variants[k].folder);
        args.push_back((dir / variants[k].folder / (sweep.plot_monitor() + ".csv")).string());
      }
    if (fs::exists(script) && run_program(args) == 0)
      logger->info("sweep plot: {}", (dir / "sweep.png").string());
    else
      logger->warn("the sweep plot could not be drawn (is python3-matplotlib installed?)");
  }
  if (stopped) return 128 + stopped;
  if (failed) {
    std::cerr << fmt::format("partita: error: {} of {} variants failed (see {}/sweep.csv)\n",
                             failed, variants.size(), dir.string());
    return 1;
  }
  std::cout << "partita run: sweep finished; " << variants.size() << " variants in " << dir.string()
            << "/ (summary sweep.csv" << (plot ? ", plot sweep.png" : "")
            << ")\n";
  return 0;
}

}  // namespace partita::app
