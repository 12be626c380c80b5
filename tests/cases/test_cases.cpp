// The generic case test: for every cases/<name>/checks.yaml, run each listed (shortened) run of a
// case through the partita executable and assert its checks. A check compares the mean of a CSV
// column over the last fraction of the rows with another column's mean, a value, or a bound, or
// reads "key=value" lines printed by a post-processing script of the case folder; `max_abs_of`
// takes the largest |value| of a column over every row instead (e.g. the energy balance error of
// energy.csv at every output time). A script check's `args` are passed after the run's output
// folder; `{out:NAME}` stands for the output folder of the earlier run NAME of the same file (a
// comparison of two runs, e.g. a collision against the driven run of the same structure). A
// run's `threads` (default 1) is its --threads.

#include <catch2/catch.hpp>

#include "../support/run_command.hpp"

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace fs = std::filesystem;

namespace {

using partita::test::quote;

std::pair<int, std::string> shell(const std::string& cmd) {
  const partita::test::CommandResult r = partita::test::run_command(cmd);
  return {r.status, r.output};
}

struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  int column(const std::string& name) const {
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return static_cast<int>(i);
    return -1;
  }
  double mean(int col, double over_last) const {
    const std::size_t n = rows.size();
    const std::size_t first =
        n - std::max<std::size_t>(1, static_cast<std::size_t>(over_last * static_cast<double>(n)));
    double s = 0;
    for (std::size_t r = first; r < n; ++r) s += rows[r][static_cast<std::size_t>(col)];
    return s / static_cast<double>(n - first);
  }
};

Csv read_csv(const fs::path& f) {
  Csv c;
  std::ifstream in(f);
  std::string line;
  if (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) c.header.push_back(cell);
  }
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) row.push_back(std::stod(cell));
    if (row.size() == c.header.size()) c.rows.push_back(row);
  }
  return c;
}

std::map<std::string, double> key_values(const std::string& text) {
  std::map<std::string, double> kv;
  std::stringstream ss(text);
  std::string line;
  while (std::getline(ss, line)) {
    const auto eq = line.find('=');
    if (eq == std::string::npos || line.find(' ') < eq) continue;
    try {
      kv[line.substr(0, eq)] = std::stod(line.substr(eq + 1));
    } catch (...) {
    }
  }
  return kv;
}

void compare(const YAML::Node& check, double value, const std::string& what,
             const std::function<double(const std::string&)>& column_mean) {
  INFO(what << " = " << value);
  if (check["equals_mean_of"]) {
    const double ref = column_mean(check["equals_mean_of"].as<std::string>());
    INFO("reference (mean of " << check["equals_mean_of"].as<std::string>() << ") = " << ref);
    CHECK(std::abs(value - ref) <= check["rel_tol"].as<double>() * std::abs(ref));
  }
  if (check["equals"]) {
    const double ref = check["equals"].as<double>();
    INFO("reference = " << ref);
    CHECK(std::abs(value - ref) <= check["rel_tol"].as<double>() * std::abs(ref));
  }
  if (check["at_most"]) CHECK(value <= check["at_most"].as<double>());
  if (check["at_least"]) CHECK(value >= check["at_least"].as<double>());
}

// The runs of every case folder `pick` accepts (two test cases, so that ctest -j runs the long
// double hull beside the others).
void run_case_checks(bool (*pick)(const std::string& folder)) {
  const fs::path root = fs::path(PARTITA_SOURCE_DIR) / "cases";
  const std::string python = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  int runs = 0;
  for (const auto& dir : fs::directory_iterator(root)) {
    const fs::path checks = dir.path() / "checks.yaml";
    if (!fs::exists(checks) || !pick(dir.path().filename().string())) continue;
    const YAML::Node doc = YAML::LoadFile(checks.string());
    // a script's `args` may name an earlier run's output folder as {out:NAME}: that folder is
    // kept until the end of the folder's runs
    auto run_named = [](const std::string& a) {  // "{out:NAME}" -> NAME, else ""
      return a.size() > 6 && a.rfind("{out:", 0) == 0 && a.back() == '}' ? a.substr(5, a.size() - 6)
                                                                         : std::string();
    };
    std::set<std::string> referenced;
    for (const YAML::Node& run : doc["runs"])
      for (const YAML::Node& check : run["checks"])
        for (const YAML::Node& arg : check["args"])
          if (const std::string n = run_named(arg.as<std::string>()); !n.empty()) referenced.insert(n);
    auto out_of = [](const std::string& name) {
      return fs::temp_directory_path() /
             ("partita_case_" + name + "_" + std::to_string(::getpid()));
    };
    for (const YAML::Node& run : doc["runs"]) {
      const std::string name = run["name"].as<std::string>();
      DYNAMIC_SECTION(dir.path().filename().string() << "/" << name) {
        ++runs;
        const fs::path out = out_of(name);
        fs::remove_all(out);
        std::string cmd =
            quote(PARTITA_EXECUTABLE) + " run " +
            quote((dir.path() / run["case"].as<std::string>()).string()) + " --output " +
            quote(out.string()) + " --threads " +
            std::to_string(run["threads"] ? run["threads"].as<int>() : 1) + " --log-level warn";
        // one run, also of a sweep case, unless the entry says `sweep: true` (its checks compare
        // the variants)
        if (!(run["sweep"] && run["sweep"].as<bool>())) cmd += " --no-sweep";
        for (const auto& s : run["set"]) cmd += " --set " + quote(s.as<std::string>());
        const auto [status, output] = shell(cmd);
        INFO("command: " << cmd << "\noutput:\n" << output);
        REQUIRE(status == 0);
        std::map<std::string, Csv> csvs;
        // a script prints all its keys at once: run each command line once per run
        std::map<std::string, std::pair<int, std::string>> script_runs;
        auto csv = [&](const std::string& file) -> const Csv& {
          if (!csvs.count(file)) csvs[file] = read_csv(out / file);
          return csvs[file];
        };
        for (const YAML::Node& check : run["checks"]) {
          if (check["script"]) {
            std::string script_cmd =
                python + " " + quote((dir.path() / check["script"].as<std::string>()).string()) +
                " " + quote(out.string());
            for (const YAML::Node& arg : check["args"]) {
              std::string a = arg.as<std::string>();
              if (const std::string other_run = run_named(a); !other_run.empty()) {
                const fs::path other = out_of(other_run);
                INFO("checks.yaml: " << a << " names a run that must come earlier in the file");
                REQUIRE(fs::is_directory(other));
                a = other.string();
              }
              script_cmd += " " + quote(a);
            }
            if (!script_runs.count(script_cmd)) script_runs[script_cmd] = shell(script_cmd);
            const auto& [st, text] = script_runs.at(script_cmd);
            INFO("script output:\n" << text);
            REQUIRE(st == 0);
            const auto kv = key_values(text);
            const std::string key = check["key"].as<std::string>();
            REQUIRE(kv.count(key) == 1);
            compare(check, kv.at(key), key, {});
            continue;
          }
          const std::string file = check["file"].as<std::string>();
          const Csv& c = csv(file);
          REQUIRE(c.rows.size() > 0);
          const double over = check["over_last"] ? check["over_last"].as<double>() : 0.2;
          auto column_mean = [&](const std::string& col) {
            const int k = c.column(col);
            INFO("column '" << col << "' of " << file);
            REQUIRE(k >= 0);
            return c.mean(k, over);
          };
          if (check["max_abs_of"]) {  // the largest |value| of a column over every row
            const std::string col = check["max_abs_of"].as<std::string>();
            const int k = c.column(col);
            INFO("column '" << col << "' of " << file);
            REQUIRE(k >= 0);
            double largest = 0.0;
            for (const auto& row : c.rows)
              largest = std::max(largest, std::abs(row[static_cast<std::size_t>(k)]));
            compare(check, largest, "largest |" + col + "| over every row of " + file,
                    column_mean);
            continue;
          }
          const std::string col = check["mean_of"].as<std::string>();
          compare(check, column_mean(col),
                  "mean of " + col + " over the last " + std::to_string(over) + " of " + file,
                  column_mean);
        }
        // an output a later run reads stays until that run is done with it
        if (!referenced.count(name)) fs::remove_all(out);
        for (const YAML::Node& check : run["checks"])
          for (const YAML::Node& arg : check["args"])
            if (const std::string n = run_named(arg.as<std::string>()); !n.empty())
              fs::remove_all(out_of(n));
      }
    }
  }
  CHECK(runs >= 0);
}

bool is_double_hull(const std::string& folder) { return folder == "double_hull_impact"; }
bool is_not_double_hull(const std::string& folder) { return !is_double_hull(folder); }

}  // namespace

TEST_CASE("cases: shortened runs meet their reference values", "[cases][slow]") {
  run_case_checks(is_not_double_hull);
}

TEST_CASE("cases: the double hull's coarse runs meet their reference values", "[cases][slow]") {
  run_case_checks(is_double_hull);
}
