// A case file's nodes (config.hpp): loading YAML with its locations, children and typed values.
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

using detail::check_value;
using detail::is_number_text;

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
