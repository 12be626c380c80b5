// The case schema (config.hpp): parameter types and constraints, Spec, validation and docs.
#include "partita/interface/config.hpp"

#include "partita/interface/log.hpp"
#include "config_checks.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <mutex>
#include <set>
#include <sstream>
#include <unordered_set>

namespace partita::config {

// ---------------------------------------------------------------------------------------------
// Types and parameters

const char* type_name(Type t) {
  switch (t) {
    case Type::real:
      return "real";
    case Type::integer:
      return "integer";
    case Type::boolean:
      return "boolean";
    case Type::string:
      return "string";
    case Type::choice:
      return "choice";
    case Type::reals:
      return "list of reals";
    case Type::integers:
      return "list of integers";
    case Type::strings:
      return "list of strings";
    case Type::section:
      return "section";
    case Type::list:
      return "list of sections";
    case Type::any:
      return "any";
  }
  return "?";
}

Param::Param(std::string key, Type type, std::string doc)
    : key_(std::move(key)), type_(type), doc_(std::move(doc)) {}

Param& Param::required(bool r) {
  required_ = r;
  return *this;
}
Param& Param::def(double v) {
  default_ = YAML::Node(v);
  return *this;
}
Param& Param::def(long v) {
  default_ = YAML::Node(v);
  return *this;
}
Param& Param::def(bool v) {
  default_ = YAML::Node(v);
  return *this;
}
Param& Param::def(const char* v) {
  return def(std::string(v));
}
Param& Param::def(std::string v) {
  default_ = YAML::Node(v);
  return *this;
}
Param& Param::def(std::vector<double> v) {
  YAML::Node n(YAML::NodeType::Sequence);
  for (double x : v) n.push_back(x);
  default_ = n;
  return *this;
}
Param& Param::unit(std::string u) {
  unit_ = std::move(u);
  return *this;
}
Param& Param::min(double v, bool exclusive) {
  min_ = {v, exclusive};
  return *this;
}
Param& Param::max(double v, bool exclusive) {
  max_ = {v, exclusive};
  return *this;
}
Param& Param::range(double lo, double hi, bool open) {
  min(lo, open);
  return max(hi, open);
}
Param& Param::typical(double lo, double hi, std::string what) {
  typical_ = Typical{lo, hi, std::move(what)};
  return *this;
}
Param& Param::choices(std::vector<std::string> names) {
  choices_ = std::move(names);
  return *this;
}
Param& Param::size(int n) {
  size_ = n;
  return *this;
}
Param& Param::spec(std::shared_ptr<const Spec> s) {
  spec_ = std::move(s);
  return *this;
}

namespace {
std::string num(double v) {
  std::ostringstream s;
  s.precision(12);
  s << v;
  return s.str();
}
}  // namespace

std::string Param::bounds_text() const {
  if (!min_ && !max_) return "";
  std::string s;
  if (min_) s += num(min_->first) + (min_->second ? " < " : " <= ");
  s += "value";
  if (max_) s += (max_->second ? " < " : " <= ") + num(max_->first);
  return s;
}

// ---------------------------------------------------------------------------------------------
// Spec

Spec::Spec(std::string name, std::string doc) : name_(std::move(name)), doc_(std::move(doc)) {}

Param& Spec::add(std::string key, Type type, std::string doc) {
  for (const auto& p : params_)
    if (p.key() == key) throw Error("spec '" + name_ + "' declares key '" + key + "' twice");
  params_.emplace_back(std::move(key), type, std::move(doc));
  return params_.back();
}

Spec& Spec::one_of(std::vector<std::string> keys, bool required) {
  one_of_.emplace_back(std::move(keys), required);
  return *this;
}

const Param* Spec::find(std::string_view key) const {
  for (const auto& p : params_)
    if (p.key() == key) return &p;
  return nullptr;
}

std::vector<std::string> Spec::keys() const {
  std::vector<std::string> k;
  for (const auto& p : params_) k.push_back(p.key());
  return k;
}

bool detail::is_number_text(const std::string& s) {
  double v;
  auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

namespace {

using detail::check_value;
using detail::is_number_text;

std::string default_text(const YAML::Node& n) {
  if (n.IsScalar()) {
    // numbers in their shortest exact form (0.3, not the 0.29999999999999999 yaml-cpp emits)
    const std::string& t = n.Scalar();
    if (!is_number_text(t)) return t;
    double v = 0.0;
    std::from_chars(t.data(), t.data() + t.size(), v);
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
  }
  if (n.IsSequence()) {
    std::string s = "[";
    for (std::size_t i = 0; i < n.size(); ++i) s += (i ? ", " : "") + default_text(n[i]);
    return s + "]";
  }
  return "";
}

void check_bounds(const Node& c, const Param& p, double v) {
  bool ok = true;
  if (p.min_bound())
    ok = ok && (p.min_bound()->second ? v > p.min_bound()->first : v >= p.min_bound()->first);
  if (p.max_bound())
    ok = ok && (p.max_bound()->second ? v < p.max_bound()->first : v <= p.max_bound()->first);
  if (!ok)
    c.fail("value " + num(v) + (p.unit_name().empty() ? "" : " " + p.unit_name()) +
           " is out of range; allowed: " + p.bounds_text() +
           (p.unit_name().empty() ? "" : " (" + p.unit_name() + ")"));
}

// A value outside the declared typical range: one warning per place in a file (a case is
// validated more than once: by check, by the run, by each sweep variant).
void check_typical(const Node& c, const Param& p, double v) {
  const auto& t = p.typical_range();
  if (!t || (v >= t->lo && v <= t->hi) || v == 0.0) return;
  const SourceLocation where = c.location();
  {
    static std::mutex m;
    static std::set<std::string> warned;
    const std::lock_guard<std::mutex> lock(m);
    if (!warned.insert(where.str() + " " + c.path()).second) return;
  }
  const std::string text = c.is_scalar() ? c.yaml().Scalar() : num(v);
  const bool bare = is_number_text(text);
  const std::string& unit = p.unit_name();
  // what was probably meant: the number as written with a prefix that brings it inside
  std::vector<std::string> meant;
  if (bare) {
    for (const char* prefix : {"G", "M", "k", "m", "u", "n"}) {
      const auto si = parse_quantity(text + " " + prefix + unit, unit);
      if (si && *si >= t->lo && *si <= t->hi && meant.size() < 2) meant.push_back(text + " " + prefix + unit);
    }
    for (const auto& [equivalent, factor] : std::vector<std::pair<std::string, double>>{
             {"g/cm^3", 1e3}}) {
      if (unit == "kg/m^3" && v * factor >= t->lo && v * factor <= t->hi && meant.size() < 2)
        meant.push_back(text + " " + equivalent);
    }
  }
  std::string message = num(v) + " " + unit + " as read" +
                        (bare ? " (a number without a unit is in " + unit + ")" : "") +
                        " is outside the " + t->what + " (" + num(t->lo) + " to " + num(t->hi) +
                        " " + unit + ")";
  if (!meant.empty()) {
    message += "; did you mean " + meant[0] + (meant.size() > 1 ? " or " + meant[1] : "") +
               "? Write the unit after the number: " + p.key() + ": " + meant[0];
  } else {
    message += "; check the value and its unit";
  }
  std::string key = c.path();
  log::get("interface")->warn("{}: key '{}': {}", where.str(), key, message);
}

void check_choice(const Node& c, const Param& p, const std::string& v) {
  if (p.allowed().empty()) return;
  for (const auto& a : p.allowed())
    if (a == v) return;
  c.fail("unknown value '" + v + "'; allowed: " + join_names(p.allowed()) +
         did_you_mean(v, p.allowed()));
}

}  // namespace

void detail::check_value(const Node& c, const Param& p) {
  switch (p.type()) {
    case Type::real: {
      const double v = c.as_real(p.unit_name());
      check_bounds(c, p, v);
      check_typical(c, p, v);
      break;
    }
    case Type::integer:
      check_bounds(c, p, static_cast<double>(c.as_integer()));
      break;
    case Type::boolean:
      c.as_boolean();
      break;
    case Type::string:
      c.as_string();
      break;
    case Type::choice:
      check_choice(c, p, c.as_string());
      break;
    case Type::reals:
    case Type::integers:
    case Type::strings: {
      if (p.type() == Type::strings && c.is_scalar() && p.length() <= 1) {  // one string: [it]
        check_choice(c, p, c.as_string());
        break;
      }
      if (!c.is_sequence())
        c.fail(std::string("expected a ") + type_name(p.type()) + " such as [1, 2, 3], found " +
               c.describe());
      if (p.length() >= 0 && static_cast<int>(c.size()) != p.length())
        c.fail("expected " + std::to_string(p.length()) + " values, found " +
               std::to_string(c.size()));
      for (const Node& e : c.items()) {
        if (p.type() == Type::reals) {
          const double v = e.as_real(p.unit_name());
          check_bounds(e, p, v);
          check_typical(e, p, v);
        } else if (p.type() == Type::integers)
          check_bounds(e, p, static_cast<double>(e.as_integer()));
        else
          check_choice(e, p, e.as_string());
      }
      break;
    }
    case Type::section:
      if (p.sub_spec())
        p.sub_spec()->validate(c);
      else if (!c.is_map())
        c.fail("expected a map, found " + c.describe());
      break;
    case Type::list:
      if (!c.is_sequence())
        c.fail("expected a list (a YAML sequence '- ...'), found " + c.describe());
      if (p.sub_spec())
        for (const Node& e : c.items()) p.sub_spec()->validate(e);
      break;
    case Type::any:
      break;
  }
}


void Spec::validate(const Node& node) const {
  if (!node.defined()) {
    // An absent or empty section: only its required keys can be wrong.
    for (const auto& p : params_)
      if (p.is_required())
        node.fail("missing required key '" + p.key() + "' (" + type_name(p.type()) +
                  (p.unit_name().empty() ? "" : ", " + p.unit_name()) + ": " + p.doc() + ")");
    return;
  }
  if (!node.is_map())
    node.fail("expected a map for " + name_ + " (" + doc_ + "), found " + node.describe());
  std::set<std::string> seen;
  const std::vector<std::string> allowed = keys();
  for (auto it = node.yaml().begin(); it != node.yaml().end(); ++it) {
    if (!it->first.IsScalar())  // load_string() rejects these; a Node made by hand may hold one
      node.fail("a key must be a plain name, found " + Node(it->first, nullptr, "").describe());
    const std::string key = it->first.Scalar();
    Node key_node(it->first, nullptr, node.path().empty() ? key : node.path() + "." + key);
    SourceLocation where{node.file(), it->first.Mark().line + 1, it->first.Mark().column + 1};
    // A key given by --set has no place in the file: say where it came from instead.
    if (const SourceLocation set = node[key].location(); set.file != node.file()) where = set;
    if (!seen.insert(key).second)
      throw Error(where, key_node.path(), "duplicate key '" + key + "' (each key may appear once)");
    if (!find(key))
      throw Error(where, key_node.path(),
                  "unknown key '" + key + "' in " + name_ +
                      "; allowed keys: " + join_names(allowed) + did_you_mean(key, allowed));
  }
  for (const auto& p : params_) {
    if (node.has(p.key()) && node[p.key()].defined()) {
      check_value(node[p.key()], p);
    } else if (p.is_required()) {
      node.fail("missing required key '" + p.key() + "' (" + type_name(p.type()) +
                (p.unit_name().empty() ? "" : ", " + p.unit_name()) + ": " + p.doc() + ")");
    }
  }
  for (const auto& [group, required] : one_of_) {
    std::vector<std::string> present;
    for (const auto& k : group)
      if (node.has(k)) present.push_back(k);
    if (present.size() > 1)
      node.fail("keys " + join_names(present) +
                " exclude each other; give only one of: " + join_names(group));
    if (required && present.empty()) node.fail("give exactly one of: " + join_names(group));
  }
}

std::string Spec::docs(int indent) const {
  const std::string pad(static_cast<std::size_t>(indent), ' ');
  std::string s = pad + name_ + ": " + doc_ + "\n";
  for (const auto& p : params_) {
    s += pad + "  " + p.key() + " (" + type_name(p.type());
    if (!p.unit_name().empty()) s += ", " + p.unit_name();
    if (p.is_required()) s += ", required";
    if (p.default_value()) s += ", default " + default_text(*p.default_value());
    s += ")";
    if (!p.allowed().empty()) s += " one of: " + join_names(p.allowed()) + ";";
    if (!p.bounds_text().empty()) s += " " + p.bounds_text() + ";";
    if (const auto& t = p.typical_range())
      s += " typically " + num(t->lo) + " to " + num(t->hi) + " " + p.unit_name() + " (" +
           t->what + ", a warning outside);";
    if (const std::string eq = equivalent_units(p.unit_name()); !eq.empty())
      s += " also in " + eq + ";";
    s += " " + p.doc() + "\n";
    if (p.sub_spec()) s += p.sub_spec()->docs(indent + 4);
  }
  for (const auto& [group, required] : one_of_)
    s += pad + "  (" + (required ? "exactly" : "at most") + " one of: " + join_names(group) + ")\n";
  return s;
}

}  // namespace partita::config
