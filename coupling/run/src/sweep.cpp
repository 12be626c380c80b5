#include "partita/run/sweep.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include <fmt/format.h>

#include "partita/interface/error.hpp"
#include "partita/interface/output.hpp"
#include "plain_name.hpp"

namespace partita::run {

using namespace coupling;  // the core this library builds on

namespace fs = std::filesystem;

std::shared_ptr<const config::Spec> Sweep::spec() {
  using config::Spec;
  auto parameter = std::make_shared<Spec>("parameter", "one swept key");
  parameter->string("key", "key path in the case file, as --set takes it (a.b[1].c)").required();
  parameter->any("values", "the values to run (YAML, e.g. [20 MPa, 200 MPa])").required();
  parameter->string("label", "name in folder names and the summary (default: the last key)");
  auto result = std::make_shared<Spec>("result", "one number per variant in sweep.csv");
  result->string("name", "column name in sweep.csv").required();
  result->string("monitor", "a declared monitor (its CSV file)").required();
  result->string("column", "participant.quantity of that monitor").required();
  result->choice("of", "which number of the column", {"final", "max", "min", "mean"}).def("final");
  auto plot = std::make_shared<Spec>("plot", "sweep.png: one monitor column of every variant");
  plot->string("monitor", "a declared monitor").required();
  plot->string("column", "participant.quantity of that monitor").required();
  plot->string("x", "participant.quantity of that monitor on the x axis (default: time)");
  plot->real("x_scale", "factor on the x values (e.g. -1000: a downward displacement in mm)")
      .def(1.0);
  plot->real("y_scale", "factor on the y values").def(1.0);
  auto s = std::make_shared<Spec>(
      "sweep",
      "run the case once per combination of values, each into DIR/<label>=<value>/ (partita run "
      "--jobs N runs N at once); DIR/sweep.csv summarises");
  s->list("parameters", "the swept keys", parameter).required();
  s->list("results", "numbers per variant for sweep.csv", result);
  s->section("plot", "overlay plot of the variants", plot);
  return s;
}

namespace {

// The keys of a YAML map node, for messages.
std::vector<std::string> map_keys(const YAML::Node& n) {
  std::vector<std::string> k;
  if (n.IsMap())
    for (auto it = n.begin(); it != n.end(); ++it) k.push_back(it->first.Scalar());
  return k;
}

// The key path must name a value that is in the case file ("a.b[2].c").
void check_key_path(const config::Node& root, const config::Node& where, const std::string& path) {
  YAML::Node n = YAML::Clone(root.yaml());
  std::string done;
  std::size_t i = 0;
  while (i < path.size()) {
    std::size_t end = path.find_first_of(".[", i);
    if (end == std::string::npos) end = path.size();
    const std::string key = path.substr(i, end - i);
    if (!key.empty()) {
      if (!n.IsMap() || !n[key]) {
        const auto known = map_keys(n);
        where.fail("the swept key '" + path + "' is not in the case file: " +
                   (done.empty() ? std::string("the top level") : "'" + done + "'") +
                   (known.empty() ? std::string(" has no keys")
                                  : " has " + join_names(known) + did_you_mean(key, known)) +
                   " (give the key a base value in the case file)");
      }
      n = n[key];
      done += (done.empty() ? "" : ".") + key;
    }
    i = end;
    while (i < path.size() && path[i] == '[') {
      const std::size_t close = path.find(']', i);
      if (close == std::string::npos) where.fail("unclosed '[' in the key path '" + path + "'");
      std::size_t index = 0;
      try {
        index = std::stoul(path.substr(i + 1, close - i - 1));
      } catch (const std::exception&) {
        where.fail("expected a whole number in [...] of the key path '" + path + "'");
      }
      if (!n.IsSequence() || index >= n.size())
        where.fail("the swept key '" + path + "': '" + done + "' has no element [" +
                   std::to_string(index) + "]");
      n = n[index];
      done += fmt::format("[{}]", index);
      i = close + 1;
    }
    if (i < path.size() && path[i] == '.') ++i;
  }
}

// The path in one spelling: "a.b[1].c" and "a.b.[1].c" alike become "a.b[1].c".
std::string normal_path(const std::string& path) {
  std::string s;
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (path[i] == '.' && i + 1 < path.size() && path[i + 1] == '[') continue;
    s += path[i];
  }
  return s;
}

// One key path inside the other (or equal): setting both sets one value twice.
bool nested_paths(const std::string& a, const std::string& b) {
  const std::string& shorter = a.size() <= b.size() ? a : b;
  const std::string& longer = a.size() <= b.size() ? b : a;
  if (longer.compare(0, shorter.size(), shorter) != 0) return false;
  return longer.size() == shorter.size() || longer[shorter.size()] == '.' ||
         longer[shorter.size()] == '[';
}

std::string folder_text(const std::string& value) {
  std::string s;
  for (char c : value)
    if (std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '+' || c == '_')
      s += c;
  return s.empty() ? std::string("value") : s;
}

}  // namespace

Sweep::Sweep(const config::Node& root) {
  const config::Node sw = root["sweep"];
  // declared monitors and their columns
  std::vector<std::string> monitors;
  std::vector<std::vector<std::string>> columns;
  for (const config::Node& m : root["monitors"].items()) {
    monitors.push_back(m.string("name"));
    columns.push_back(m.strings("quantities"));
  }
  auto check_column = [&](const config::Node& n) {
    const std::string mon = n.string("monitor");
    const auto it = std::find(monitors.begin(), monitors.end(), mon);
    if (it == monitors.end())
      n["monitor"].fail("no monitor '" + mon + "' is declared; monitors: " +
                        (monitors.empty() ? std::string("none") : join_names(monitors)) +
                        did_you_mean(mon, monitors));
    const auto& cols = columns[static_cast<std::size_t>(it - monitors.begin())];
    const std::string col = n.string("column");
    if (std::find(cols.begin(), cols.end(), col) == cols.end())
      n["column"].fail("monitor '" + mon + "' has no column '" + col + "'; it has " +
                       join_names(cols) + did_you_mean(col, cols));
  };

  for (const config::Node& p : sw["parameters"].items()) {
    Parameter par;
    par.key = p.string("key");
    check_key_path(root, p["key"], par.key);
    if (par.key.rfind("sweep", 0) == 0) p["key"].fail("the sweep cannot sweep itself");
    for (const auto& other : parameters_)
      if (nested_paths(normal_path(other.key), normal_path(par.key)))
        p["key"].fail(
            normal_path(other.key) == normal_path(par.key)
                ? "the key '" + par.key +
                      "' is swept twice: each variant would set it twice and only the second "
                      "value would run; list all its values in one parameter"
                : "the keys '" + other.key + "' and '" + par.key +
                      "' are both swept, and one lies inside the other: each variant would set "
                      "the inner value twice; sweep one of them");
    if (p.has("label")) {
      par.label = p.string("label");
      check_plain_name(p["label"], par.label, "the sweep label");
    } else {  // the key's last name, brackets as '_' ("loads[0]" -> "loads_0")
      for (const char c : par.key.substr(par.key.find_last_of('.') == std::string::npos
                                             ? 0
                                             : par.key.find_last_of('.') + 1))
        if (c != ']') par.label += c == '[' ? '_' : c;
      check_plain_name(p["key"], par.label,
                       "the sweep label (the key's last name; or give label:)");
    }
    const config::Node values = p["values"];
    if (!values.is_sequence() || values.size() == 0)
      values.fail("expected a non-empty list of values, e.g. [1, 2, 3]; found " +
                  values.describe());
    for (const config::Node& v : values.items()) {
      YAML::Emitter e;
      e << YAML::Flow << v.yaml();
      par.values.push_back(e.c_str());
      par.origins.push_back(v.location());
    }
    for (const auto& other : parameters_)
      if (other.label == par.label)
        p.fail("two swept parameters have the label '" + par.label + "'; give one a label");
    parameters_.push_back(std::move(par));
  }
  if (parameters_.empty()) sw["parameters"].fail("a sweep needs at least one parameter");
  for (const config::Node& r : sw["results"].items()) {
    check_column(r);
    results_.push_back(
        Result{r.string("name"), r.string("monitor"), r.string("column"), r.string("of")});
  }
  if (sw.has("plot")) {
    check_column(sw["plot"]);
    plot_monitor_ = sw["plot"].string("monitor");
    plot_column_ = sw["plot"].string("column");
    if (sw["plot"].has("x")) {
      const std::string x = sw["plot"].string("x");
      const auto it = std::find(monitors.begin(), monitors.end(), plot_monitor_);
      const auto& cols = columns[static_cast<std::size_t>(it - monitors.begin())];
      if (std::find(cols.begin(), cols.end(), x) == cols.end())
        sw["plot"]["x"].fail("monitor '" + plot_monitor_ + "' has no column '" + x + "'; it has " +
                             join_names(cols) + did_you_mean(x, cols));
      plot_x_ = x;
    }
    plot_x_scale_ = sw["plot"].real("x_scale");
    plot_y_scale_ = sw["plot"].real("y_scale");
  }

  // full factorial, the first parameter slowest
  std::size_t total = 1;
  for (const auto& p : parameters_) total *= p.values.size();
  if (total > 10000) sw.fail(fmt::format("{} variants is more than 10000", total));
  for (std::size_t k = 0; k < total; ++k) {
    Variant v;
    std::size_t rest = k;
    std::vector<std::size_t> index(parameters_.size());
    for (std::size_t i = parameters_.size(); i-- > 0;) {
      index[i] = rest % parameters_[i].values.size();
      rest /= parameters_[i].values.size();
    }
    for (std::size_t i = 0; i < parameters_.size(); ++i) {
      const std::string& value = parameters_[i].values[index[i]];
      v.overrides.push_back(parameters_[i].key + "=" + value);
      v.values.push_back(value);
      v.folder += (i ? "," : "") + parameters_[i].label + "=" + folder_text(value);
    }
    variants_.push_back(std::move(v));
  }
}

double Sweep::evaluate(const Result& r, const fs::path& variant_dir) const {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::ifstream in(variant_dir / (r.monitor + ".csv"));
  std::string line;
  if (!std::getline(in, line)) return nan;
  // header cells are "name [unit]" or "name"
  int col = -1, i = 0;
  std::stringstream hs(line);
  for (std::string cell; std::getline(hs, cell, ','); ++i) {
    const auto bracket = cell.find(" [");
    if ((bracket == std::string::npos ? cell : cell.substr(0, bracket)) == r.column) col = i;
  }
  if (col < 0) return nan;
  double final = nan, max = -1e300, min = 1e300, sum = 0.0;
  long n = 0;
  while (std::getline(in, line)) {
    std::stringstream rs(line);
    std::string cell;
    for (int c = 0; c <= col && std::getline(rs, cell, ','); ++c) {
    }
    double v = nan;
    try {
      v = std::stod(cell);
    } catch (const std::exception&) {
      continue;
    }
    final = v;
    max = std::max(max, v);
    min = std::min(min, v);
    sum += v;
    ++n;
  }
  if (n == 0) return nan;
  if (r.of == "max") return max;
  if (r.of == "min") return min;
  if (r.of == "mean") return sum / static_cast<double>(n);
  return final;
}

void Sweep::write_summary(const fs::path& dir, const std::vector<std::string>& status) const {
  auto csv_text = [](std::string s) {
    for (auto& c : s)
      if (c == '\n' || c == '\r') c = ' ';
    if (s.find_first_of(",\"") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
  };
  std::string text = "variant";
  for (const auto& p : parameters_) (text += ',') += csv_text(p.label);
  text += ",status";
  for (const auto& r : results_) (text += ',') += csv_text(r.name);
  text += "\n";
  for (std::size_t k = 0; k < variants_.size(); ++k) {
    const Variant& v = variants_[k];
    text += csv_text(v.folder);
    for (const auto& value : v.values) (text += ',') += csv_text(value);
    const std::string st = k < status.size() ? status[k] : std::string("not run");
    (text += ',') += csv_text(st);
    for (const auto& r : results_) {
      const double x =
          st == "ok" ? evaluate(r, dir / v.folder) : std::numeric_limits<double>::quiet_NaN();
      text += ',';
      if (!std::isnan(x)) text += fmt::format("{:.10g}", x);
    }
    text += "\n";
  }
  write_file_atomically(dir / "sweep.csv", text);
}

}  // namespace partita::run
