// partita: the command line. A thin main over the libraries:
//   partita run CASE.yaml [--output DIR] [--threads N] [--log-level L]
//   partita check CASE.yaml
//   partita list
//   partita docs [NAME]
// Exit status 0 on success; 1 with one clear message on any user error; 2 on usage errors.

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>

#include <CLI/CLI.hpp>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "partita/adapters/register_all.hpp"
#include "partita/coupling/case_run.hpp"
#include "partita/coupling/registries.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"
#include "partita/interface/stl.hpp"
#include "partita/interface/version.hpp"

namespace {

using partita::coupling::Registries;

Registries make_registries() {
  Registries r;
  partita::coupling::register_builtin(r);
  partita::adapters::register_all(r);
  return r;
}

// Visit every registry with its heading.
template <class F>
void for_each_registry(const Registries& r, F&& f) {
  f("solvers", r.solvers);
  f("mappers", r.mappers);
  f("schemes", r.schemes);
  f("accelerations", r.accelerations);
  f("convergence measures", r.convergence_measures);
}

// `partita check FILE.stl`: read and validate a triangle mesh, print what it holds.
int check_stl(const std::string& file) {
  const partita::Mesh m = partita::read_stl(file, "mesh");
  const auto box = m.bounding_box();
  std::cout << "partita check: " << file << " is a valid STL: " << m.num_triangles()
            << " triangles, " << m.size() << " distinct vertices, area " << m.total_area()
            << " m^2 (if in metres), bounding box [" << box.min.transpose() << "] .. ["
            << box.max.transpose() << "]\n";
  return 0;
}

bool is_stl(const std::string& file) {
  std::string ext = std::filesystem::path(file).extension().string();
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".stl";
}

// PNG plots of the run's CSV time series, drawn by the bundled matplotlib script. A missing
// python3/matplotlib costs the plots only, never the run.
void plot_csv_files(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  std::vector<std::string> csvs;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".csv") csvs.push_back(e.path().string());
  if (csvs.empty()) return;
  fs::path script = PARTITA_PLOT_SCRIPT;
  if (!fs::exists(script))
    script = fs::canonical("/proc/self/exe").parent_path() / "../share/partita/plot_monitors.py";
  if (!fs::exists(script)) return;
  const std::string python = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  std::string cmd = python + " '" + script.string() + "'";
  for (const auto& c : csvs) cmd += " '" + c + "'";
  cmd += " >/dev/null";
  if (std::system(cmd.c_str()) != 0)
    partita::log::get("app")->warn(
        "plotting the CSV files failed (is python3-matplotlib installed?)");
  else
    partita::log::get("app")->info("plots: {}/*.png", dir.string());
}

// The case's post-processing scripts (output.scripts), with the output folder as argument.
void run_scripts(const std::vector<std::filesystem::path>& scripts,
                 const std::filesystem::path& dir) {
  const std::string python =
      std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  for (const auto& s : scripts) {
    const std::string cmd = python + " '" + s.string() + "' '" + dir.string() + "'";
    partita::log::get("app")->info("post-processing: {}", s.filename().string());
    if (std::system(cmd.c_str()) != 0)
      partita::log::get("app")->warn("post-processing script {} failed", s.string());
  }
}

int list(const Registries& r) {
  for_each_registry(r, [](const char* heading, const auto& reg) {
    std::cout << heading << ":\n";
    std::size_t w = 0;
    for (const auto& e : reg.entries()) w = std::max(w, e.name.size());
    for (const auto& e : reg.entries())
      std::cout << "  " << e.name << std::string(w + 2 - e.name.size(), ' ') << e.doc << "\n";
  });
  return 0;
}

int docs(const Registries& r, const std::string& name) {
  if (name.empty() || name == "case") {
    std::cout << partita::coupling::case_spec(r)->docs() << "\n"
              << "Each registered name has its own page: partita docs NAME (see partita list).\n";
    return 0;
  }
  bool found = false;
  std::vector<std::string> all;
  for_each_registry(r, [&](const char* heading, const auto& reg) {
    for (const auto& e : reg.entries()) {
      all.push_back(e.name);
      if (e.name != name) continue;
      found = true;
      std::cout << e.name << " (" << reg.kind() << "): " << e.doc << "\n";
      if (e.spec)
        std::cout << e.spec->docs(2);
      else
        std::cout << "  (no parameters)\n";
    }
  });
  if (!found)
    throw partita::Error("no documentation for '" + name +
                         "': it is not a registered name; known names: " +
                         partita::join_names(all) + partita::did_you_mean(name, all));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "partita: partitioned coupling of simulation codes (DEM granules and FEM structures first)"};
  app.set_version_flag("--version", std::string("partita ") + partita::version());
  app.require_subcommand(1);
  std::string log_level = "info";
  app.add_option("--log-level", log_level,
                 "Log level: trace, debug, info, warn, error, critical, off")
      ->capture_default_str();

  std::string case_file, output_dir, doc_name;
  int threads = 0;
  auto* run =
      app.add_subcommand("run", "Run a case: partita run CASE.yaml [--output DIR] [--threads N]");
  run->add_option("case", case_file, "The case file (YAML)")->required();
  run->add_option("-o,--output", output_dir, "Output folder (default: out/<case name>/)");
  run->add_option("-t,--threads", threads, "Threads for the solvers (default: all cores)")
      ->check(CLI::PositiveNumber);
  run->add_option("--log-level", log_level,
                  "Log level: trace, debug, info, warn, error, critical, off");
  std::vector<std::string> overrides;
  run->add_option("--set", overrides,
                  "Change a value of the case: KEY.PATH=VALUE (e.g. time.end=0.01, "
                  "participants.plate.loads[0].pressure='20 kPa'); repeatable")
      ->take_all();
  auto* check =
      app.add_subcommand("check", "Validate a case completely without running it (or an STL file)");
  check->add_option("case", case_file, "The case file (YAML), or an STL mesh (.stl)")->required();
  check->add_option("--log-level", log_level, "Log level");
  check
      ->add_option("--set", overrides,
                   "Change a value of the case before checking it: KEY.PATH=VALUE")
      ->take_all();
  app.add_subcommand(
      "list", "List every registered solver, mapper, scheme, acceleration and convergence measure");
  auto* doc =
      app.add_subcommand("docs", "The parameter reference, generated from the declarations");
  doc->add_option("name", doc_name, "A registered name (see partita list), or 'case' (default)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }

  try {
    partita::log::set_level(partita::log::parse_level(log_level));
    const Registries registries = make_registries();
    if (app.got_subcommand("list")) return list(registries);
    if (app.got_subcommand("docs")) return docs(registries, doc_name);

    partita::coupling::RunOptions options;
    options.output_dir = output_dir;
    options.overrides = overrides;
#ifdef _OPENMP
    options.threads = threads > 0 ? threads : omp_get_num_procs();
    omp_set_num_threads(options.threads);
#else
    options.threads = threads > 0 ? threads : 1;
#endif
    if (app.got_subcommand("check")) {
      if (is_stl(case_file)) return check_stl(case_file);
      options.check_only = true;
      partita::coupling::CaseRun c(case_file, registries, options);
      std::cout << "partita check: " << case_file << " is valid\n";
      return 0;
    }
    partita::coupling::CaseRun c(case_file, registries, options);
    c.run();
    plot_csv_files(c.output_dir());
    run_scripts(c.scripts(), c.output_dir());
    std::cout << "partita run: finished; output in " << c.output_dir().string()
              << "/ (CSV time series and their "
              << "PNG plots; VTK series for ParaView in vtk/*.pvd)\n";
    return 0;
  } catch (const partita::Error& e) {
    std::cerr << "partita: error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "partita: error: " << e.what() << "\n";
    return 1;
  }
}
