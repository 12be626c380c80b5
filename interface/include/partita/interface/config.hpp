#pragma once
// Typed access to YAML input driven by parameter declarations.
//
// A component declares its parameters once, in a Spec (key, type, default, allowed values, unit,
// one line of doc). Spec::validate() checks a YAML map against it: unknown keys ("did you
// mean"), missing required keys, wrong types, values out of range or not among the allowed
// ones. Every error names the file, line and column, the key path, the value found and what is
// allowed. The same declarations produce the text of `partita docs`.
//
//   config::Spec spec("material", "An isotropic elastic material");
//   spec.real("youngs_modulus", "Young's modulus").unit("Pa").positive().required();
//   spec.real("poisson_ratio", "Poisson's ratio").range(-1.0, 0.5, /*open=*/true).required();
//   spec.real("density", "Mass density").unit("kg/m^3").positive().def(1000.0);
//   config::Node m = node["material"].validated(spec);
//   double E = m.real("youngs_modulus");      // "200 MPa" in the file gives 2.0e8
//   double rho = m.real("density");           // the default if absent
//
// Reals may carry a unit after the number ("10 kPa", "2 mm") when the parameter declares a unit:
// the unit must be the declared one with an SI prefix (G, M, k, c (for m only), m, u, n), or one
// of the usual equivalents (N/mm^2 for Pa, g/cm^3 and t/mm^3 for kg/m^3, km/h for m/s, ...), and
// it is converted explicitly to SI. A number with digit groups ("210,000") is refused with the
// ways to write it.

#include <deque>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>
#include <Eigen/Core>

#include "partita/interface/error.hpp"

namespace partita::config {

enum class Type {
  real,      ///< a floating-point number (optionally with a unit)
  integer,   ///< a whole number
  boolean,   ///< true / false
  string,    ///< free text (file names, ...)
  choice,    ///< one of the declared names
  reals,     ///< a sequence of reals (fixed length if size() is set)
  integers,  ///< a sequence of integers
  strings,   ///< a sequence of strings (each among the choices, if declared)
  section,   ///< a map validated with its own Spec
  list,      ///< a sequence of maps, each validated with its own Spec
  any,       ///< anything; the owner validates it later (e.g. one-of sections)
};

/// "real", "integer", ... for messages and docs.
const char* type_name(Type t);

class Spec;

/// One declared parameter. The chained setters return *this.
class Param {
 public:
  Param(std::string key, Type type, std::string doc);

  Param& required(bool r = true);
  Param& def(double v);
  Param& def(long v);
  Param& def(int v) { return def(static_cast<long>(v)); }
  Param& def(bool v);
  Param& def(const char* v);
  Param& def(std::string v);
  Param& def(std::vector<double> v);
  Param& unit(std::string u);
  Param& min(double v, bool exclusive = false);
  Param& max(double v, bool exclusive = false);
  Param& positive() { return min(0.0, true); }
  Param& non_negative() { return min(0.0, false); }
  /// min < value < max (open = true) or min <= value <= max.
  Param& range(double lo, double hi, bool open = false);
  /// The values a physical input takes in practice, in SI (for Young's modulus: soft rubber to
  /// diamond). A value outside is accepted with a warning that names the key, the value as read
  /// in SI and, where a unit prefix brings it inside, what was probably meant ("210 GPa"): a
  /// number without a unit is in SI, and a modulus written in GPa without its unit is 1e9 too
  /// small. `what` names the range in the message ("Young's moduli of solids").
  Param& typical(double lo, double hi, std::string what);
  Param& choices(std::vector<std::string> names);
  Param& size(int n);  ///< exact length of a reals/integers/strings sequence
  Param& spec(std::shared_ptr<const Spec> s);  ///< for section and list

  const std::string& key() const { return key_; }
  Type type() const { return type_; }
  const std::string& doc() const { return doc_; }
  bool is_required() const { return required_; }
  bool has_default() const { return default_.has_value(); }
  /// The default as YAML (scalar or sequence), if any.
  const std::optional<YAML::Node>& default_value() const { return default_; }
  const std::string& unit_name() const { return unit_; }
  const std::optional<std::pair<double, bool>>& min_bound() const { return min_; }
  const std::optional<std::pair<double, bool>>& max_bound() const { return max_; }
  struct Typical {
    double lo, hi;
    std::string what;
  };
  const std::optional<Typical>& typical_range() const { return typical_; }
  const std::vector<std::string>& allowed() const { return choices_; }
  int length() const { return size_; }
  const std::shared_ptr<const Spec>& sub_spec() const { return spec_; }

  /// "0 < value < 0.5" style text, or "" when unbounded.
  std::string bounds_text() const;

 private:
  std::string key_;
  Type type_;
  std::string doc_;
  bool required_ = false;
  std::optional<YAML::Node> default_;
  std::string unit_;
  std::optional<std::pair<double, bool>> min_, max_;  // value, exclusive
  std::optional<Typical> typical_;
  std::vector<std::string> choices_;
  int size_ = -1;
  std::shared_ptr<const Spec> spec_;
};

class Node;

/// The declared parameters of one component or section.
class Spec {
 public:
  Spec(std::string name, std::string doc);

  Param& add(std::string key, Type type, std::string doc);
  Param& real(std::string key, std::string doc) {
    return add(std::move(key), Type::real, std::move(doc));
  }
  Param& integer(std::string key, std::string doc) {
    return add(std::move(key), Type::integer, std::move(doc));
  }
  Param& boolean(std::string key, std::string doc) {
    return add(std::move(key), Type::boolean, std::move(doc));
  }
  Param& string(std::string key, std::string doc) {
    return add(std::move(key), Type::string, std::move(doc));
  }
  Param& choice(std::string key, std::string doc, std::vector<std::string> names) {
    return add(std::move(key), Type::choice, std::move(doc)).choices(std::move(names));
  }
  Param& reals(std::string key, std::string doc) {
    return add(std::move(key), Type::reals, std::move(doc));
  }
  Param& integers(std::string key, std::string doc) {
    return add(std::move(key), Type::integers, std::move(doc));
  }
  Param& strings(std::string key, std::string doc) {
    return add(std::move(key), Type::strings, std::move(doc));
  }
  Param& section(std::string key, std::string doc, std::shared_ptr<const Spec> s) {
    return add(std::move(key), Type::section, std::move(doc)).spec(std::move(s));
  }
  Param& list(std::string key, std::string doc, std::shared_ptr<const Spec> s) {
    return add(std::move(key), Type::list, std::move(doc)).spec(std::move(s));
  }
  Param& any(std::string key, std::string doc) {
    return add(std::move(key), Type::any, std::move(doc));
  }

  /// Keys of this spec may also be absent in favour of a one-of choice: at most one of `keys`
  /// may be present; `required` asks for exactly one.
  Spec& one_of(std::vector<std::string> keys, bool required = true);

  const std::string& name() const { return name_; }
  const std::string& doc() const { return doc_; }
  const std::deque<Param>& params() const { return params_; }
  const Param* find(std::string_view key) const;
  std::vector<std::string> keys() const;

  /// Check a node against this spec, recursively through section/list parameters.
  /// Throws partita::Error naming file, line, column, key path, value and what is allowed.
  void validate(const Node& node) const;

  /// The parameter reference (Markdown-like plain text), nested sections indented.
  std::string docs(int indent = 0) const;

 private:
  std::string name_;
  std::string doc_;
  std::deque<Param> params_;  // deque: references returned by add() stay valid
  std::vector<std::pair<std::vector<std::string>, bool>> one_of_;
};

/// Typical ranges (SI) of the bulk properties of solids, for Param::typical(): Young's modulus
/// from soft rubbers and gels (0.1 MPa) to diamond (1.2 TPa), density from polymer foams
/// (10 kg/m^3) to osmium (22,600 kg/m^3).
inline constexpr double kSolidModulusLow = 1e5, kSolidModulusHigh = 1.2e12;
inline constexpr const char* kSolidModulusWhat = "Young's moduli of solids (soft rubber to diamond)";
inline constexpr double kSolidDensityLow = 10.0, kSolidDensityHigh = 2.3e4;
inline constexpr const char* kSolidDensityWhat = "densities of solids (polymer foams to osmium)";

/// The units accepted for a parameter declared in `unit`, besides the SI prefixes: "N/mm^2, ..."
/// ("" when none).
std::string equivalent_units(std::string_view unit);

/// Convert "10 kPa" / "2 mm" / "3.5" to SI for a parameter whose unit is `unit`.
/// Returns nullopt when the text is not a number followed by an allowed unit; `why` says what.
std::optional<double> parse_quantity(std::string_view text, std::string_view unit,
                                     std::string* why = nullptr);

/// A position in a YAML document: the node, the file it came from and its key path.
/// Cheap to copy. Typed getters check types (and ranges, when a Spec is attached).
class Node {
 public:
  Node() = default;
  Node(YAML::Node node, std::shared_ptr<const std::string> file, std::string path,
       std::shared_ptr<const Spec> spec = nullptr);

  /// Parse a YAML file; syntax errors become partita::Error with file, line and column.
  static Node load_file(const std::filesystem::path& file);
  /// Parse a YAML file, then apply assignments "a.b[2].c=VALUE" (VALUE is YAML: a number, a
  /// string, [a, b] or {k: v}); a missing key is created, a bad path is a partita::Error.
  /// `origins`, where given (one per assignment), is where each assignment comes from (a sweep
  /// value in the case file): messages about that key name it instead of the command line.
  static Node load_file(const std::filesystem::path& file,
                        const std::vector<std::string>& overrides,
                        const std::vector<SourceLocation>& origins = {});
  /// Parse YAML text; `name` stands for the file name in messages.
  static Node load_string(const std::string& text, const std::string& name = "<string>");

  // --- shape -----------------------------------------------------------------------------
  bool defined() const { return node_.IsDefined() && !node_.IsNull(); }
  bool is_map() const { return node_.IsMap(); }
  bool is_sequence() const { return node_.IsSequence(); }
  bool is_scalar() const { return node_.IsScalar(); }
  std::size_t size() const { return node_.size(); }

  // --- navigation ------------------------------------------------------------------------
  /// True if the map has the key (defaults do not count).
  bool has(std::string_view key) const;
  /// The child at `key`. If absent, the declared default (if any) or an undefined node.
  Node operator[](std::string_view key) const;
  /// The i-th element of a sequence.
  Node operator[](std::size_t i) const;
  /// The elements of a sequence (a missing node gives none).
  std::vector<Node> items() const;
  /// The keys of a map, in file order.
  std::vector<std::string> keys() const;

  /// Validate against `spec` and return the same node with the spec attached (for defaults and
  /// range checks of the getters). Children reached through section/list params get theirs.
  Node validated(std::shared_ptr<const Spec> spec) const;
  Node validated(const Spec& spec) const;  ///< copies the spec

  // --- typed values of children (throw if missing and no default) -------------------------
  double real(std::string_view key) const;
  long integer(std::string_view key) const;
  bool boolean(std::string_view key) const;
  std::string string(std::string_view key) const;
  std::vector<double> reals(std::string_view key) const;
  std::vector<long> integers(std::string_view key) const;
  std::vector<std::string> strings(std::string_view key) const;
  Eigen::Vector3d vec3(std::string_view key) const;
  /// Optional getters: the value if present (or defaulted), else nullopt.
  std::optional<double> real_opt(std::string_view key) const;
  std::optional<std::string> string_opt(std::string_view key) const;

  // --- typed values of this node --------------------------------------------------------
  double as_real(std::string_view unit = "") const;
  long as_integer() const;
  bool as_boolean() const;
  std::string as_string() const;
  std::vector<double> as_reals(std::string_view unit = "") const;
  Eigen::Vector3d as_vec3(std::string_view unit = "") const;

  // --- where ------------------------------------------------------------------------------
  const std::string& path() const { return path_; }
  const std::string& file() const;
  SourceLocation location() const;
  const YAML::Node& yaml() const { return node_; }
  const Spec* spec() const { return spec_.get(); }
  /// "the value found" for messages: the scalar, or "a map" / "a sequence".
  std::string describe() const;

  /// Throw partita::Error at this node: "file:line:col: key 'path': message".
  [[noreturn]] void fail(const std::string& message) const;

 private:
  Node child(std::string_view key, const YAML::Node& n, bool from_default) const;
  const Param* param(std::string_view key) const;
  void check_param(const Param& p) const;  // range/choices/length of this node's value

  YAML::Node node_;
  std::shared_ptr<const std::string> file_;
  std::string path_;
  std::shared_ptr<const Spec> spec_;
  SourceLocation fallback_;  // where a missing (defaulted) node would have been
  // key paths set by --set, each with where it came from (empty file: the command line)
  std::shared_ptr<const std::vector<std::pair<std::string, SourceLocation>>> overridden_;
};

}  // namespace partita::config
