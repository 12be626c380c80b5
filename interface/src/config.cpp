#include "partita/interface/config.hpp"

#include "partita/interface/log.hpp"

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

namespace {

bool is_number_text(const std::string& s);

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

// Checks of one value against its parameter declaration (shared by validate() and getters).
void check_value(const Node& c, const Param& p);

bool is_number_text(const std::string& s) {
  double v;
  auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
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

void check_value(const Node& c, const Param& p) {
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

}  // namespace

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

// ---------------------------------------------------------------------------------------------
// Quantities with units

namespace {
// Units a structures or process engineer writes for a declared SI unit, with their factor to it
// (besides the SI prefixes, which parse_quantity() handles for every unit).
const std::vector<std::pair<std::string, double>>& equivalents(std::string_view unit) {
  static const std::vector<std::pair<std::string, double>> none;
  static const std::vector<std::pair<std::string, double>> pressure = {
      {"N/mm^2", 1e6}, {"N/m^2", 1.0},   {"kN/m^2", 1e3}, {"kN/mm^2", 1e9},
      {"MN/m^2", 1e6}, {"N/cm^2", 1e4}, {"bar", 1e5},    {"mbar", 1e2}};
  static const std::vector<std::pair<std::string, double>> density = {
      {"g/cm^3", 1e3}, {"kg/dm^3", 1e3}, {"t/m^3", 1e3}, {"t/mm^3", 1e12}, {"kg/mm^3", 1e9},
      {"g/m^3", 1e-3}};
  static const std::vector<std::pair<std::string, double>> speed = {
      {"km/h", 1.0 / 3.6}, {"m/ms", 1e3}, {"mm/ms", 1.0}};
  static const std::vector<std::pair<std::string, double>> energy = {
      {"N m", 1.0}, {"Nm", 1.0}, {"N mm", 1e-3}, {"Nmm", 1e-3}, {"kN m", 1e3}};
  static const std::vector<std::pair<std::string, double>> frequency = {{"1/s", 1.0}};
  static const std::vector<std::pair<std::string, double>> rate = {{"Hz", 1.0}};
  if (unit == "Pa") return pressure;
  if (unit == "kg/m^3") return density;
  if (unit == "m/s") return speed;
  if (unit == "J") return energy;
  if (unit == "Hz") return frequency;
  if (unit == "1/s") return rate;
  return none;
}
}  // namespace

std::optional<double> parse_quantity(std::string_view text, std::string_view unit,
                                     std::string* why) {
  auto trim = [](std::string_view s) {
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
    return s;
  };
  text = trim(text);
  double value = 0;
  const char* begin = text.data();
  const char* end = text.data() + text.size();
  if (!text.empty() && text.front() == '+') ++begin;
  auto r = std::from_chars(begin, end, value);
  if (r.ec != std::errc()) {
    if (why)
      *why = r.ec == std::errc::result_out_of_range
                 ? "out of the range of a real number; allowed: a magnitude between about "
                   "2.2e-308 and 1.8e308"
                 : "not a number";
    return std::nullopt;
  }
  if (!std::isfinite(value)) {
    if (why) *why = "not a finite number";
    return std::nullopt;
  }
  const std::string_view rest(r.ptr, static_cast<std::size_t>(end - r.ptr));
  // Digit groups ("210,000", "210 000", "0,3"): a comma is a thousands separator to some readers
  // and a decimal one to others, so neither is guessed.
  const bool comma_group = rest.size() >= 2 && rest[0] == ',' && std::isdigit(static_cast<unsigned char>(rest[1]));
  const std::string_view after_space = trim(rest);
  const bool space_group = !comma_group && rest.size() > after_space.size() && !after_space.empty() &&
                           std::isdigit(static_cast<unsigned char>(after_space[0]));
  if (comma_group || space_group) {
    if (why) {
      std::string digits(text.substr(0, static_cast<std::size_t>(r.ptr - text.data())));
      std::string tail;
      std::size_t i = 0;
      const std::string_view r2 = comma_group ? rest : after_space;
      std::string groups;
      for (; i < r2.size() && (std::isdigit(static_cast<unsigned char>(r2[i])) || r2[i] == ',' ||
                               r2[i] == ' ');
           ++i)
        if (r2[i] != ',' && r2[i] != ' ') groups += r2[i];
      tail = std::string(trim(r2.substr(i)));
      const std::string u = tail.empty() ? std::string() : " " + tail;
      *why = "'" + std::string(text) + "' has digit groups separated by " +
             (comma_group ? "a comma" : "a space") +
             ", which partita reads neither as a thousands nor as a decimal separator; write " +
             digits + groups + u + (comma_group ? " if the comma groups thousands, or " + digits +
                                                      "." + groups + u + " if it is a decimal comma"
                                                : "") +
             " (a point is the decimal separator; 2.1e5 is 210000)";
    }
    return std::nullopt;
  }
  std::string normalised(trim(rest));
  // superscripts and a power written without a caret (N/mm², N/mm2) as in the declared units
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"\xC2\xB2", "^2"}, {"\xC2\xB3", "^3"}})
    for (auto pos = normalised.find(from); pos != std::string::npos; pos = normalised.find(from))
      normalised.replace(pos, from.size(), to);
  if (normalised.size() >= 2 && (normalised.back() == '2' || normalised.back() == '3') &&
      std::isalpha(static_cast<unsigned char>(normalised[normalised.size() - 2])))
    normalised.insert(normalised.size() - 1, "^");
  const std::string_view token = normalised;
  if (token.empty()) return value;
  if (unit.empty()) {
    if (why) *why = "'" + std::string(token) + "' follows the number, but this value takes no unit";
    return std::nullopt;
  }
  if (token == unit) return value;
  // The value in SI: a finite number may overflow (1e308 GPa) or vanish (1e-320 nm) on the way.
  const auto converted = [&](double si) -> std::optional<double> {
    if (std::isfinite(si) && (si != 0.0 || value == 0.0)) return si;
    if (why)
      *why = "'" + std::string(text) + "' is " + (std::isfinite(si) ? "zero" : "infinite") +
             " after conversion to " + std::string(unit) + "; allowed: a magnitude in " +
             std::string(unit) + " between about 2.2e-308 and 1.8e308";
    return std::nullopt;
  };
  static const std::vector<std::pair<std::string, double>> prefixes = {
      {"G", 1e9},  {"M", 1e6},  {"k", 1e3},         {"c", 1e-2},
      {"m", 1e-3}, {"u", 1e-6}, {"\xC2\xB5", 1e-6}, {"n", 1e-9}};
  // The base symbol: a declared unit that itself carries a prefix (kg) is rebased (g).
  std::string base(unit);
  double base_factor = 1.0;
  if (base.size() > 1 && base[0] == 'k' && base.substr(1, 1) == "g") {
    base = base.substr(1);
    base_factor = 1e-3;
  }
  // Power of the first symbol (m^2, m^3): the prefix is raised to it.
  int power = 1;
  const auto slash = base.find('/');
  const auto caret = base.find('^');
  if (caret != std::string::npos && (slash == std::string::npos || caret < slash) &&
      caret + 1 < base.size())
    power = base[caret + 1] - '0';
  for (const auto& [p, f] : prefixes) {
    if (token == p + base) return converted(value * std::pow(f, power) * base_factor);
  }
  if (base_factor != 1.0 && token == base) return converted(value * base_factor);
  for (const auto& [name, factor] : equivalents(unit))
    if (token == name) return converted(value * factor);
  if (why) {
    const std::string eq = equivalent_units(unit);
    *why = "unit '" + std::string(token) + "' is not allowed here; the unit is " +
           std::string(unit) + " (SI prefixes G, M, k, m, u, n may precede it" +
           (eq.empty() ? std::string() : "; also " + eq) + ")";
  }
  return std::nullopt;
}

std::string equivalent_units(std::string_view unit) {
  std::string s;
  for (const auto& [name, factor] : equivalents(unit)) s += (s.empty() ? "" : ", ") + name;
  return s;
}

// ---------------------------------------------------------------------------------------------
// Node

namespace {
const std::string& empty_string() {
  static const std::string s;
  return s;
}
}  // namespace

Node::Node(YAML::Node node, std::shared_ptr<const std::string> file, std::string path,
           std::shared_ptr<const Spec> spec)
    : node_(std::move(node)),
      file_(std::move(file)),
      path_(std::move(path)),
      spec_(std::move(spec)) {}

namespace {

// What yaml-cpp accepts but a case file may not hold: keys that are not plain scalars (a sequence
// or a map used as a key), and a quoted string left open (yaml-cpp ends it at the end of the
// file, so it swallows every key after it). `text` is the source (null: not checked for quotes).
class DocumentCheck {
 public:
  DocumentCheck(const std::string* text, std::string name) : text_(text), name_(std::move(name)) {}

  void walk(const YAML::Node& n, const std::string& path, int depth = 0) {
    // Aliases may repeat a node, or nest it in itself ('&a [*a]'): bounds on the size and the
    // depth keep the walk of such a document short.
    if (depth > kMaxDepth) {
      throw Error(where(n), path.size() > 60 ? path.substr(0, 60) + "..." : path,
                  "values nested more than " + std::to_string(kMaxDepth) +
                      " levels deep (an alias '*name' inside its own anchor '&name'?); allowed: "
                      "at most " +
                      std::to_string(kMaxDepth) + " levels");
    }
    if (++visited_ > kMaxNodes) {
      throw Error(where(n), path,
                  "the document holds more than " + std::to_string(kMaxNodes) +
                      " values (aliases '*name' repeating an anchor '&name'?); allowed: a case "
                      "of at most that size");
    }
    if (n.IsScalar()) {
      check_quotes(n, path);
    } else if (n.IsSequence()) {
      for (std::size_t i = 0; i < n.size(); ++i)
        walk(n[i], path + "[" + std::to_string(i) + "]", depth + 1);
    } else if (n.IsMap()) {
      for (auto it = n.begin(); it != n.end(); ++it) {
        const YAML::Node key = it->first;  // a copy: `it->` yields a temporary
        if (!key.IsScalar()) {
          const std::string what = key.IsSequence() ? "a sequence"
                                   : key.IsMap()    ? "a map"
                                                    : "an empty (null) key";
          throw Error(where(key), path,
                      "a key must be a plain name, found " + what +
                          " used as a key (e.g. '[a, b]: ...' or '? ...'); write 'name: value'");
        }
        check_quotes(key, path);
        walk(it->second, path.empty() ? key.Scalar() : path + "." + key.Scalar(), depth + 1);
      }
    }
  }

 private:
  static constexpr std::size_t kMaxNodes = 1'000'000;
  static constexpr int kMaxDepth = 100;

  SourceLocation where(const YAML::Node& n) const {
    const YAML::Mark m = n.Mark();
    return m.line >= 0 ? SourceLocation{name_, m.line + 1, m.column + 1} : SourceLocation{name_};
  }

  void check_quotes(const YAML::Node& n, const std::string& path) {
    if (!text_ || n.Tag() != "!") return;  // "!": a quoted (non-plain) scalar
    const YAML::Mark m = n.Mark();
    // yaml-cpp counts positions in bytes after a UTF-8 byte order mark, if any
    const std::size_t bom = text_->rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;
    if (m.pos < 0 || static_cast<std::size_t>(m.pos) + bom >= text_->size()) return;
    const auto at = static_cast<std::size_t>(m.pos) + bom;
    const char q = (*text_)[at];
    if (q != '"' && q != '\'') return;
    if (!checked_.insert(at).second) return;  // an alias repeats a scalar: scan its text once
    for (std::size_t i = at + 1; i < text_->size(); ++i) {
      const char c = (*text_)[i];
      if (q == '"' && c == '\\') {
        ++i;  // an escaped character
      } else if (c == q) {
        if (q == '\'' && i + 1 < text_->size() && (*text_)[i + 1] == '\'') {
          ++i;  // '' is a quote inside single quotes
        } else {
          return;
        }
      }
    }
    throw Error(where(n), path,
                std::string("unterminated quoted string: the ") + q +
                    " opened here is never closed, so the string runs to the end of the file "
                    "and swallows every key after it; add the closing " +
                    q);
  }

  const std::string* text_;
  std::string name_;
  std::size_t visited_ = 0;
  std::unordered_set<std::size_t> checked_;  // positions of the quoted scalars scanned
};

// The innermost '{' or '[' still open at byte `stop` of a YAML text (quoted strings and
// comments skipped): where a missing '}' or ']' belongs. yaml-cpp reports a flow collection
// that is never closed where it gave up looking, often a line or more later.
std::optional<std::pair<SourceLocation, char>> unclosed_bracket(const std::string& text,
                                                                std::size_t stop,
                                                                const std::string& name) {
  struct Open {
    char c;
    int line, column;
  };
  std::vector<Open> open;
  int line = 1, column = 0;
  char quote = 0;
  bool comment = false;
  char previous = '\n';
  for (std::size_t i = 0; i < text.size() && i < stop; ++i) {
    const char c = text[i];
    ++column;
    if (c == '\n') {
      ++line;
      column = 0;
      comment = false;
      previous = c;
      continue;
    }
    if (comment) continue;
    if (quote) {
      if (quote == '"' && c == '\\') {
        ++i;
        ++column;
      } else if (c == quote) {
        quote = 0;
      }
    } else if (c == '#' && (previous == ' ' || previous == '\t' || previous == '\n')) {
      comment = true;
    } else if (c == '"' || c == '\'') {
      if (previous == ' ' || previous == '\t' || previous == '\n' || previous == '{' ||
          previous == '[' || previous == ',' || previous == ':')
        quote = c;
    } else if (c == '{' || c == '[') {
      open.push_back({c, line, column});
    } else if ((c == '}' || c == ']') && !open.empty()) {
      open.pop_back();
    }
    previous = c;
  }
  if (open.empty()) return std::nullopt;
  return std::pair{SourceLocation{name, open.back().line, open.back().column}, open.back().c};
}

}  // namespace

Node Node::load_string(const std::string& text, const std::string& name) {
  auto file = std::make_shared<const std::string>(name);
  try {
    YAML::Node root = YAML::Load(text);
    DocumentCheck(&text, name).walk(root, "");
    Node n(root, file, "");
    n.fallback_ = SourceLocation{name, 1, 1};
    return n;
  } catch (const YAML::Exception& e) {
    if (e.msg.find("flow") != std::string::npos) {
      const std::size_t stop =
          e.mark.pos >= 0 ? static_cast<std::size_t>(e.mark.pos) + 1 : text.size();
      if (const auto at = unclosed_bracket(text, stop, name)) {
        const bool map = at->second == '{';
        throw Error(at->first, "",
                    std::string("YAML syntax error: the '") + (map ? "{" : "[") +
                        "' opened here is never closed; add the '" + (map ? "}" : "]") +
                        "' where the " + (map ? "map" : "list") + " ends (the parser gave up at line " +
                        std::to_string(e.mark.line + 1) + ": " + e.msg + ")");
      }
    }
    throw Error(SourceLocation{name, e.mark.line + 1, e.mark.column + 1}, "",
                "YAML syntax error: " + e.msg + " (check indentation, colons and brackets)");
  }
}

Node Node::load_file(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec))
    throw Error("cannot open '" + file.string() + "': no such file");
  if (std::filesystem::is_directory(file, ec))
    throw Error("cannot read '" + file.string() + "': it is a directory, a YAML file is expected");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error("cannot open '" + file.string() + "' for reading");
  std::stringstream ss;
  ss << in.rdbuf();
  return load_string(ss.str(), file.string());
}

Node Node::load_file(const std::filesystem::path& file, const std::vector<std::string>& overrides,
                     const std::vector<SourceLocation>& origins) {
  Node n = load_file(file);
  if (overrides.empty()) return n;
  std::vector<std::pair<std::string, SourceLocation>> overridden;
  if (!n.node_.IsDefined() || n.node_.IsNull()) n.node_ = YAML::Node(YAML::NodeType::Map);
  for (const std::string& a : overrides) {
    const auto eq = a.find('=');
    if (eq == std::string::npos || eq == 0)
      throw Error(
          "--set '" + a +
          "': expected KEY.PATH=VALUE, e.g. time.end=0.01 or coupling.exchanges[0].mapper=rbf");
    const std::string path = a.substr(0, eq);
    const std::size_t index = overridden.size();
    overridden.emplace_back(path, index < origins.size() ? origins[index] : SourceLocation{});
    YAML::Node value;
    try {
      value = YAML::Load(a.substr(eq + 1));
    } catch (const YAML::Exception& e) {
      throw Error("--set '" + a + "': the value is not valid YAML: " + e.msg);
    }
    // Walk the path: names separated by '.', indices in brackets.
    std::vector<YAML::Node> chain{n.node_};
    std::size_t i = 0;
    std::string walked;
    while (i < path.size()) {
      YAML::Node cur = chain.back();
      if (path[i] == '[') {
        const auto close = path.find(']', i);
        if (close == std::string::npos)
          throw Error("--set '" + a + "': unclosed '[' in the key path");
        const std::string idx = path.substr(i + 1, close - i - 1);
        std::size_t k = 0;
        try {
          k = std::stoul(idx);
        } catch (...) {
          throw Error("--set '" + a + "': index '" + idx + "' is not a number");
        }
        if (!cur.IsSequence() || k >= cur.size())
          throw Error("--set '" + a + "': '" + walked + "' has no element [" + idx + "]" +
                      (cur.IsSequence() ? " (it has " + std::to_string(cur.size()) + ")"
                                        : " (not a list)"));
        walked += "[" + idx + "]";
        i = close + 1;
        if (i < path.size() && path[i] == '.') ++i;
        if (i >= path.size()) {
          cur[k] = value;
          break;
        }
        chain.push_back(cur[k]);
        continue;
      }
      auto end = path.find_first_of(".[", i);
      if (end == std::string::npos) end = path.size();
      const std::string key = path.substr(i, end - i);
      if (key.empty()) throw Error("--set '" + a + "': empty key in the path");
      if (cur.IsSequence() && key.find_first_not_of("0123456789") == std::string::npos)
        throw Error("--set '" + a + "': '" + walked + "' is a list; its element " + key +
                    " is written '" + walked + "[" + key +
                    "]' (list indices go in brackets, e.g. participants.plate.loads[0].pressure)");
      if (cur.IsDefined() && !cur.IsNull() && !cur.IsMap())
        throw Error("--set '" + a + "': '" + walked + "' is not a map, it cannot have key '" + key +
                    "'");
      walked += (walked.empty() ? "" : ".") + key;
      i = end < path.size() && path[end] == '.' ? end + 1 : end;
      if (end >= path.size()) {
        cur[key] = value;
        break;
      }
      chain.push_back(cur[key]);
    }
  }
  DocumentCheck(nullptr, "command line (--set)").walk(n.node_, "");
  n.overridden_ =
      std::make_shared<const std::vector<std::pair<std::string, SourceLocation>>>(
          std::move(overridden));
  return n;
}

const std::string& Node::file() const {
  return file_ ? *file_ : empty_string();
}

SourceLocation Node::location() const {
  if (overridden_)
    for (const auto& [p, origin] : *overridden_)
      if (path_ == p || path_.rfind(p + ".", 0) == 0 || path_.rfind(p + "[", 0) == 0)
        return origin.file.empty() ? SourceLocation{"command line (--set " + p + "=...)", 0, 0}
                                   : origin;
  if (node_.IsDefined()) {
    const YAML::Mark m = node_.Mark();
    if (m.line >= 0) return SourceLocation{file(), m.line + 1, m.column + 1};
  }
  SourceLocation f = fallback_;
  if (f.file.empty()) f.file = file();
  return f;
}

std::string Node::describe() const {
  if (!node_.IsDefined() || node_.IsNull()) return "nothing";
  if (node_.IsScalar()) return "'" + node_.Scalar() + "'";
  if (node_.IsMap()) return "a map";
  if (node_.IsSequence()) return "a sequence";
  return "?";
}

void Node::fail(const std::string& message) const {
  throw Error(location(), path_, message);
}

const Param* Node::param(std::string_view key) const {
  return spec_ ? spec_->find(key) : nullptr;
}

Node Node::child(std::string_view key, const YAML::Node& n, bool from_default) const {
  std::string p = path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  std::shared_ptr<const Spec> s;
  if (const Param* pr = param(key); pr && pr->type() == Type::section) s = pr->sub_spec();
  Node c(n, file_, std::move(p), s);
  c.fallback_ = location();
  c.overridden_ = overridden_;
  if (const Param* pr = param(key); pr && pr->type() == Type::list && pr->sub_spec()) {
    // Items of a declared list get the item spec: remember it through a one-param wrapper.
    auto w = std::make_shared<Spec>(pr->key(), pr->doc());
    w->list("[]", pr->doc(), pr->sub_spec());
    c.spec_ = w;
  }
  (void)from_default;
  return c;
}

bool Node::has(std::string_view key) const {
  if (!node_.IsDefined() || !node_.IsMap()) return false;
  for (auto it = node_.begin(); it != node_.end(); ++it)
    if (it->first.Scalar() == key) return true;
  return false;
}

Node Node::operator[](std::string_view key) const {
  if (node_.IsDefined() && !node_.IsNull() && !node_.IsMap())
    fail("expected a map containing '" + std::string(key) + "', found " + describe());
  if (node_.IsDefined() && node_.IsMap()) {
    for (auto it = node_.begin(); it != node_.end(); ++it)
      if (it->first.Scalar() == key) return child(key, it->second, false);
  }
  if (const Param* p = param(key); p && p->default_value())
    return child(key, *p->default_value(), true);
  return child(key, YAML::Node(YAML::NodeType::Undefined), false);
}

Node Node::operator[](std::size_t i) const {
  if (!node_.IsDefined() || !node_.IsSequence()) fail("expected a sequence, found " + describe());
  if (i >= node_.size())
    fail("index " + std::to_string(i) + " is past the end of a sequence of " +
         std::to_string(node_.size()));
  std::shared_ptr<const Spec> s;
  if (spec_ && spec_->params().size() == 1 && spec_->params().front().key() == "[]")
    s = spec_->params().front().sub_spec();
  Node c(node_[i], file_, path_ + "[" + std::to_string(i) + "]", s);
  c.fallback_ = location();
  c.overridden_ = overridden_;
  return c;
}

std::vector<Node> Node::items() const {
  std::vector<Node> v;
  if (!defined()) return v;
  if (!node_.IsSequence())
    fail("expected a sequence ('- ...' items or [a, b]), found " + describe());
  for (std::size_t i = 0; i < node_.size(); ++i) v.push_back((*this)[i]);
  return v;
}

std::vector<std::string> Node::keys() const {
  std::vector<std::string> k;
  if (!defined()) return k;
  if (!node_.IsMap()) fail("expected a map, found " + describe());
  for (auto it = node_.begin(); it != node_.end(); ++it) k.push_back(it->first.Scalar());
  return k;
}

Node Node::validated(std::shared_ptr<const Spec> spec) const {
  spec->validate(*this);
  Node n = *this;
  n.spec_ = std::move(spec);
  return n;
}

Node Node::validated(const Spec& spec) const {
  return validated(std::make_shared<const Spec>(spec));
}

// --- typed values of this node ---------------------------------------------------------------

double Node::as_real(std::string_view unit) const {
  if (!defined())
    fail("missing value; expected a real number" +
         (unit.empty() ? std::string() : " [" + std::string(unit) + "]"));
  if (!node_.IsScalar()) fail("expected a real number, found " + describe());
  std::string why;
  auto v = parse_quantity(node_.Scalar(), unit, &why);
  if (!v)
    fail("expected a real number" + (unit.empty() ? std::string() : " in " + std::string(unit)) +
         ", found " + describe() + " (" + why + ")");
  return *v;
}

long Node::as_integer() const {
  if (!defined()) fail("missing value; expected an integer");
  if (!node_.IsScalar()) fail("expected an integer, found " + describe());
  const std::string& s = node_.Scalar();
  long v = 0;
  const char* b = s.data();
  if (!s.empty() && s[0] == '+') ++b;
  auto r = std::from_chars(b, s.data() + s.size(), v);
  if (r.ec == std::errc::result_out_of_range)
    fail("integer " + describe() +
         " is out of range; allowed: " + std::to_string(std::numeric_limits<long>::min()) + " to " +
         std::to_string(std::numeric_limits<long>::max()));
  if (r.ec != std::errc() || r.ptr != s.data() + s.size())
    fail("expected an integer, found " + describe() +
         (is_number_text(s) ? " (a whole number is required)" : ""));
  return v;
}

bool Node::as_boolean() const {
  if (!defined()) fail("missing value; expected true or false");
  if (!node_.IsScalar()) fail("expected true or false, found " + describe());
  std::string s = node_.Scalar();
  for (auto& ch : s) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  if (s == "true" || s == "yes" || s == "on") return true;
  if (s == "false" || s == "no" || s == "off") return false;
  fail("expected true or false, found " + describe());
}

std::string Node::as_string() const {
  if (!defined()) fail("missing value; expected a string");
  if (!node_.IsScalar()) fail("expected a string, found " + describe());
  return node_.Scalar();
}

std::vector<double> Node::as_reals(std::string_view unit) const {
  if (!defined()) fail("missing value; expected a list of reals");
  if (!node_.IsSequence()) fail("expected a list of reals such as [0, 0, 1], found " + describe());
  std::vector<double> v;
  for (const Node& e : items()) v.push_back(e.as_real(unit));
  return v;
}

Eigen::Vector3d Node::as_vec3(std::string_view unit) const {
  const std::vector<double> v = as_reals(unit);
  if (v.size() != 3) fail("expected 3 values [x, y, z], found " + std::to_string(v.size()));
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

// --- typed values of children ----------------------------------------------------------------

void Node::check_param(const Param& p) const {
  check_value(*this, p);
}

namespace {
[[noreturn]] void missing(const Node& parent, std::string_view key, const Param* p) {
  std::string what = "missing required key '" + std::string(key) + "'";
  if (p)
    what += " (" + std::string(type_name(p->type())) +
            (p->unit_name().empty() ? "" : ", " + p->unit_name()) + ": " + p->doc() + ")";
  parent.fail(what);
}
}  // namespace

double Node::real(std::string_view key) const {
  Node c = (*this)[key];
  const Param* p = param(key);
  if (!c.defined()) missing(*this, key, p);
  if (p) c.check_param(*p);
  return c.as_real(p ? std::string_view(p->unit_name()) : std::string_view());
}

long Node::integer(std::string_view key) const {
  Node c = (*this)[key];
  const Param* p = param(key);
  if (!c.defined()) missing(*this, key, p);
  if (p) c.check_param(*p);
  return c.as_integer();
}

bool Node::boolean(std::string_view key) const {
  Node c = (*this)[key];
  if (!c.defined()) missing(*this, key, param(key));
  return c.as_boolean();
}

std::string Node::string(std::string_view key) const {
  Node c = (*this)[key];
  const Param* p = param(key);
  if (!c.defined()) missing(*this, key, p);
  if (p) c.check_param(*p);
  return c.as_string();
}

std::vector<double> Node::reals(std::string_view key) const {
  Node c = (*this)[key];
  const Param* p = param(key);
  if (!c.defined()) missing(*this, key, p);
  if (p) c.check_param(*p);
  return c.as_reals(p ? std::string_view(p->unit_name()) : std::string_view());
}

std::vector<long> Node::integers(std::string_view key) const {
  Node c = (*this)[key];
  const Param* p = param(key);
  if (!c.defined()) missing(*this, key, p);
  if (p) c.check_param(*p);
  std::vector<long> v;
  for (const Node& e : c.items()) v.push_back(e.as_integer());
  return v;
}

std::vector<std::string> Node::strings(std::string_view key) const {
  Node c = (*this)[key];
  const Param* p = param(key);
  if (!c.defined()) missing(*this, key, p);
  if (p) c.check_param(*p);
  if (c.is_scalar()) return {c.as_string()};
  std::vector<std::string> v;
  for (const Node& e : c.items()) v.push_back(e.as_string());
  return v;
}

Eigen::Vector3d Node::vec3(std::string_view key) const {
  Node c = (*this)[key];
  const Param* p = param(key);
  if (!c.defined()) missing(*this, key, p);
  if (p) c.check_param(*p);
  return c.as_vec3(p ? std::string_view(p->unit_name()) : std::string_view());
}

std::optional<double> Node::real_opt(std::string_view key) const {
  Node c = (*this)[key];
  if (!c.defined()) return std::nullopt;
  return real(key);
}

std::optional<std::string> Node::string_opt(std::string_view key) const {
  Node c = (*this)[key];
  if (!c.defined()) return std::nullopt;
  return string(key);
}

}  // namespace partita::config
