#pragma once
// Material laws by name. Each law's file defines its class and its entry (name, one line of
// doc, its parameters as plain data, a factory from their values); register_material_laws()
// adds the built-in entries, one line each (no static self-registration). A program that reads
// cases (the FEM adapter) turns the parameters into its own input keys and documentation, and a
// plugin adds entries of its own. Plain data only: no YAML, no files.
//
//   MaterialLawRegistry laws;
//   register_material_laws(laws);
//   MaterialParameters p;
//   p.set("youngs_modulus", 210e9).set("poisson_ratio", 0.3).set("density", 7850);
//   std::shared_ptr<const MaterialLaw> law = laws.get("neo-hooke").create(p);

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "partita/fem/error.hpp"
#include "partita/fem/material_law.hpp"

namespace partita::fem {

// One parameter of a law: a number (`columns` empty) or a table of rows of numbers, one column
// per entry of `columns` (a hardening curve: plastic strain, yield stress).
struct MaterialParameter {
  std::string name;  // snake_case, as a case file spells it ("youngs_modulus")
  std::string unit;  // SI ("Pa", "kg/m^3"); empty for a pure number
  std::string doc;   // what it is, one line
  // allowed range of a number (a table's cells: its columns' ranges)
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_exclusive = false, max_exclusive = false;
  std::optional<double> default_value;  // used when the value is not given
  bool is_required = false;             // an error when not given (and no default)
  // A typical range, for documentation and plausibility warnings (absent: none).
  std::optional<std::pair<double, double>> typical_range;
  std::string typical_what;  // what the typical range covers ("Young's moduli of solids")
  // A table parameter: its columns, each a number parameter (name, unit, doc, range, typical
  // range; every cell of the column is required), and what one row is (for documentation).
  std::vector<MaterialParameter> columns;
  std::string row_name, row_doc;  // "hardening_point", "a point of the hardening curve"

  // A number: MaterialParameter::number("density", "kg/m^3", "mass density").positive().required()
  static MaterialParameter number(std::string name, std::string unit, std::string doc) {
    MaterialParameter p;
    p.name = std::move(name);
    p.unit = std::move(unit);
    p.doc = std::move(doc);
    return p;
  }
  // A table of rows, one value per column; `row_name` and `row_doc` say what a row is.
  static MaterialParameter table(std::string name, std::string doc, std::string row_name,
                                 std::string row_doc, std::vector<MaterialParameter> columns) {
    MaterialParameter p = number(std::move(name), "", std::move(doc));
    p.row_name = std::move(row_name);
    p.row_doc = std::move(row_doc);
    p.columns = std::move(columns);
    return p;
  }
  MaterialParameter& required() {
    is_required = true;
    return *this;
  }
  MaterialParameter& def(double v) {
    default_value = v;
    return *this;
  }
  MaterialParameter& positive() { return lower(0.0, true); }
  MaterialParameter& non_negative() { return lower(0.0, false); }
  MaterialParameter& lower(double v, bool exclusive) {
    min = v;
    min_exclusive = exclusive;
    return *this;
  }
  // lo < v < hi (open) or lo <= v <= hi
  MaterialParameter& range(double lo, double hi, bool open) {
    lower(lo, open);
    max = hi;
    max_exclusive = open;
    return *this;
  }
  MaterialParameter& typical(double lo, double hi, std::string what) {
    typical_range = std::pair{lo, hi};
    typical_what = std::move(what);
    return *this;
  }

  bool is_table() const { return !columns.empty(); }
  bool allows(double v) const {
    if (std::isnan(v)) return false;
    if (min_exclusive ? !(v > min) : !(v >= min)) return false;
    if (max_exclusive ? !(v < max) : !(v <= max)) return false;
    return true;
  }
  // "> 0", "in (-1, 0.5)", ">= 0": the allowed range as text
  std::string range_text() const {
    std::ostringstream s;
    const bool lo = std::isfinite(min), hi = std::isfinite(max);
    if (lo && hi) {
      s << "in " << (min_exclusive ? "(" : "[") << min << ", " << max << (max_exclusive ? ")" : "]");
    } else if (lo) {
      s << (min_exclusive ? "> " : ">= ") << min;
    } else if (hi) {
      s << (max_exclusive ? "< " : "<= ") << max;
    } else {
      s << "any number";
    }
    return s.str();
  }
};

// The values of a law's parameters, by name.
class MaterialParameters {
 public:
  using Table = std::vector<std::vector<double>>;
  MaterialParameters& set(std::string name, double value) {
    values_[std::move(name)] = value;
    return *this;
  }
  MaterialParameters& set_table(std::string name, Table rows) {
    tables_[std::move(name)] = std::move(rows);
    return *this;
  }
  bool has(std::string_view name) const {
    return values_.find(std::string(name)) != values_.end() ||
           tables_.find(std::string(name)) != tables_.end();
  }
  // The value of a number; Error when it is not given.
  double real(std::string_view name) const {
    const auto it = values_.find(std::string(name));
    if (it == values_.end()) throw Error("material parameter '" + std::string(name) + "' not given");
    return it->second;
  }
  const Table& table(std::string_view name) const {
    const auto it = tables_.find(std::string(name));
    if (it == tables_.end()) throw Error("material table '" + std::string(name) + "' not given");
    return it->second;
  }
  const std::map<std::string, double>& values() const { return values_; }
  const std::map<std::string, Table>& tables() const { return tables_; }

 private:
  std::map<std::string, double> values_;
  std::map<std::string, Table> tables_;
};

using MaterialLawFactory =
    std::function<std::shared_ptr<const MaterialLaw>(const MaterialParameters&)>;

// A rule between a law's parameters that the given values break, and where: the parameter it is
// about (empty: the parameters as a whole, e.g. one of two forms missing), a table's row
// (0-based; -1: the whole parameter) and column (empty: the whole row), and the other parameters
// the rule reads, so that a program reading a case can point at the key and name the others'
// lines. The message states the rule and the values, and names the law.
struct MaterialParameterIssue {
  std::string parameter;
  int row = -1;
  std::string column;
  std::vector<std::string> related;
  std::string message;
};

// The rules between parameters of one law (each value already in its range, defaults filled in):
// the first one broken, or nothing.
using MaterialLawCheck =
    std::function<std::optional<MaterialParameterIssue>(const MaterialParameters&)>;

// One law: what a case names it, what it is, its parameters and how to build it.
struct MaterialLawEntry {
  std::string name;
  std::string doc;  // one line
  std::vector<MaterialParameter> parameters;
  // Called with every declared parameter checked (given ones in range, required ones present,
  // defaults filled in) and `check` passed; may throw Error for what it alone can tell.
  MaterialLawFactory factory;
  // The rules between parameters (a yield stress below Young's modulus, one of two forms of the
  // hardening); empty: none.
  MaterialLawCheck check = {};

  const MaterialParameter* find(std::string_view parameter) const {
    for (const auto& p : parameters)
      if (p.name == parameter) return &p;
    return nullptr;
  }

  // The given values checked against the declarations (known names, ranges, required ones
  // present) with the defaults filled in. Error("<law>: ...") states the rule and the value.
  MaterialParameters completed(const MaterialParameters& given) const {
    MaterialParameters p = given;
    for (const auto& [key, v] : given.values()) {
      const MaterialParameter* d = find(key);
      if (d == nullptr || d->is_table())
        throw Error(name + ": unknown parameter '" + key + "'; its parameters: " + names());
      if (!d->allows(v)) {
        std::ostringstream s;
        s << name << ": " << key << " must be " << d->range_text() << ", got " << v;
        throw Error(s.str());
      }
    }
    for (const auto& [key, rows] : given.tables()) {
      const MaterialParameter* d = find(key);
      if (d == nullptr || !d->is_table())
        throw Error(name + ": unknown table '" + key + "'; its parameters: " + names());
      for (std::size_t r = 0; r < rows.size(); ++r) {
        const auto& row = rows[r];
        if (row.size() != d->columns.size())
          throw Error(name + ": each row of " + key + " has " + std::to_string(d->columns.size()) +
                      " values (" + column_names(*d) + "), got one of " +
                      std::to_string(row.size()));
        for (std::size_t c = 0; c < row.size(); ++c)
          if (!d->columns[c].allows(row[c])) {
            std::ostringstream s;
            s << name << ": " << key << " row " << r << ": " << d->columns[c].name << " must be "
              << d->columns[c].range_text() << ", got " << row[c];
            throw Error(s.str());
          }
      }
    }
    for (const auto& d : parameters) {
      if (p.has(d.name)) continue;
      if (d.default_value) {
        p.set(d.name, *d.default_value);
      } else if (d.is_required) {
        throw Error(name + ": parameter '" + d.name + "' (" + d.doc + ") is required");
      }
    }
    return p;
  }

  // The first rule between the parameters that `complete` (completed()'s values) breaks.
  std::optional<MaterialParameterIssue> issue(const MaterialParameters& complete) const {
    if (!check) return std::nullopt;
    return check(complete);
  }

  // completed(), issue() (an Error with its message), then the factory.
  std::shared_ptr<const MaterialLaw> create(const MaterialParameters& given) const {
    const MaterialParameters p = completed(given);
    if (auto broken = issue(p)) throw Error(broken->message);
    return factory(p);
  }

  std::string names() const {
    std::string s;
    for (const auto& d : parameters) s += (s.empty() ? "" : ", ") + d.name;
    return s;
  }
  static std::string column_names(const MaterialParameter& table) {
    std::string s;
    for (const auto& c : table.columns) s += (s.empty() ? "" : ", ") + c.name;
    return s;
  }
};

// The laws known to a program. add() refuses a name given twice; get() names the known ones.
class MaterialLawRegistry {
 public:
  void add(MaterialLawEntry entry) {
    if (entry.name.empty()) throw Error("material law registry: a law without a name");
    if (!entry.factory) throw Error("material law '" + entry.name + "': no factory");
    if (find(entry.name) != nullptr)
      throw Error("material law '" + entry.name + "' is registered twice");
    entries_.push_back(std::move(entry));
  }
  const MaterialLawEntry* find(std::string_view name) const {
    for (const auto& e : entries_)
      if (e.name == name) return &e;
    return nullptr;
  }
  // The entry, or Error "unknown material law 'x'; known material laws: a, b, c".
  const MaterialLawEntry& get(std::string_view name) const {
    if (const auto* e = find(name)) return *e;
    throw Error("unknown material law '" + std::string(name) + "'; known material laws: " +
                join(names()));
  }
  std::vector<std::string> names() const {
    std::vector<std::string> n;
    for (const auto& e : entries_) n.push_back(e.name);
    return n;
  }
  const std::vector<MaterialLawEntry>& entries() const { return entries_; }

 private:
  static std::string join(const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
    return s;
  }
  std::vector<MaterialLawEntry> entries_;
};

// The isotropic constants every built-in law takes (Young's modulus, Poisson's ratio, density),
// with their ranges and typical values: what a new law's entry usually starts from.
std::vector<MaterialParameter> isotropic_parameters();

// Adds the built-in laws, one line each (src/register_material_laws.cpp).
void register_material_laws(MaterialLawRegistry& registry);

}  // namespace partita::fem
