#pragma once
// A solver's monitor quantities, each declared once: its name, unit and doc (the rows of its
// `partita docs` page, which the conformance check holds the reported values to) and how to get
// its value. The same table gives the documentation and the values, so the two cannot drift.
//
//   const MonitorTable<MySolver>& MySolver::monitor_table() {
//     static const MonitorTable<MySolver> t = [] {
//       MonitorTable<MySolver> t;
//       t.scalar("kinetic_energy", "J", "1/2 m v^2", [](const MySolver& s) { return s.ke(); });
//       t.add(xyz_rows("<mesh>.force", "N", "force on a mesh"),
//             [](const MySolver& s, const MonitorTable<MySolver>::Out& out) {
//               for (const auto& m : s.meshes_) out({m.name}, m.force);  // lid.force_x, ...
//             });
//       return t;
//     }();
//     return t;
//   }
//   // registration:   r.solvers.add("my-solver", "...", create, spec(), monitor_table().docs());
//   // the values:     return monitor_table().values(*this, names);
//
// A row's name may hold placeholders in angle brackets for a family of quantities ("<mesh>.work":
// one per mesh); a getter names each member by the texts that replace them, in order. An entry is
// computed only when one of the names asked for matches one of its rows (quantity_matches), so an
// expensive quantity (an energy over a whole mesh) costs nothing in a run that does not record
// it; an entry with a condition (`when`) reports nothing while it is false (energies that are not
// tracked, breakage that is off). The values come entry by entry, in the table's order.

#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "partita/interface/registry.hpp"
#include "partita/interface/solver.hpp"

namespace partita {

/// The three rows of a vector quantity: name + "_x" with `doc`, then "_y" and "_z" documented
/// "... y" and "... z" (the separator may be another, e.g. "." for "particle.<id>.x").
inline std::vector<QuantityDoc> xyz_rows(const std::string& name, const std::string& unit,
                                         const std::string& doc, const std::string& sep = "_") {
  return {{name + sep + "x", unit, doc}, {name + sep + "y", unit, "... y"},
          {name + sep + "z", unit, "... z"}};
}

template <class S>
class MonitorTable {
 public:
  /// Where a getter puts the values of its entry.
  class Out {
   public:
    /// One value per row of the entry, in order, for the member whose placeholders' texts are
    /// `texts` (none for a single quantity).
    void operator()(std::initializer_list<std::string_view> texts,
                    std::initializer_list<double> values) const {
      std::size_t r = 0;
      for (const double v : values) row(r++, texts, v);
    }
    /// The three rows of a vector (xyz_rows).
    void operator()(std::initializer_list<std::string_view> texts, const Eigen::Vector3d& v) const {
      (*this)(texts, {v.x(), v.y(), v.z()});
    }
    /// The value of row `r` alone (a row that not every member has).
    void row(std::size_t r, std::initializer_list<std::string_view> texts, double value) const {
      const QuantityDoc& d = rows_[r];
      out_.push_back({fill(d.name, texts), d.unit, value});
    }

   private:
    friend class MonitorTable;
    Out(const std::vector<QuantityDoc>& rows, std::vector<MonitorValue>& out)
        : rows_(rows), out_(out) {}
    const std::vector<QuantityDoc>& rows_;
    std::vector<MonitorValue>& out_;
  };
  using Getter = void (*)(const S&, const Out&);
  using When = bool (*)(const S&);

  /// An entry: its documentation rows and the getter that gives their values (through Out);
  /// with `when`, only while when(solver) holds.
  MonitorTable& add(std::vector<QuantityDoc> rows, Getter get, When when = nullptr) {
    entries_.push_back({std::move(rows), get, nullptr, when});
    return *this;
  }
  /// A single quantity (a name without placeholders) and its value.
  MonitorTable& scalar(std::string name, std::string unit, std::string doc,
                       double (*value)(const S&), When when = nullptr) {
    entries_.push_back({{{std::move(name), std::move(unit), std::move(doc)}}, nullptr, value, when});
    return *this;
  }

  /// Every row, in order: the solver's `partita docs` list (Registry's quantities).
  std::vector<QuantityDoc> docs() const {
    std::vector<QuantityDoc> d;
    for (const auto& e : entries_) d.insert(d.end(), e.rows.begin(), e.rows.end());
    return d;
  }

  /// The values of the quantities named (all of them when `names` is empty), computing only the
  /// entries that one of the names matches (Solver::monitor_values).
  std::vector<MonitorValue> values(const S& s, const std::vector<std::string>& names) const {
    std::vector<MonitorValue> v;
    for (const auto& e : entries_) {
      if (e.when && !e.when(s)) continue;
      if (!names.empty() && !asked(e, names)) continue;
      if (e.value)
        v.push_back({e.rows.front().name, e.rows.front().unit, e.value(s)});
      else
        e.get(s, Out(e.rows, v));
    }
    if (names.empty()) return v;
    std::vector<MonitorValue> out;  // only those asked for (an entry gives all its rows)
    for (auto& m : v)
      for (const auto& n : names)
        if (m.name == n) {
          out.push_back(std::move(m));
          break;
        }
    return out;
  }

 private:
  struct Entry {
    std::vector<QuantityDoc> rows;
    Getter get;
    double (*value)(const S&);
    When when;
  };
  static bool asked(const Entry& e, const std::vector<std::string>& names) {
    for (const auto& r : e.rows)
      for (const auto& n : names)
        if (quantity_matches(r, n)) return true;
    return false;
  }
  // `pattern` with its placeholders "<...>" replaced by `texts`, in order
  static std::string fill(const std::string& pattern, std::initializer_list<std::string_view> texts) {
    std::string name;
    auto t = texts.begin();
    for (std::size_t i = 0; i < pattern.size();) {
      const std::size_t open = pattern.find('<', i);
      if (open == std::string::npos || t == texts.end()) {
        name.append(pattern, i, std::string::npos);
        break;
      }
      name.append(pattern, i, open - i);
      name.append(*t++);
      i = pattern.find('>', open) + 1;
    }
    return name;
  }

  std::vector<Entry> entries_;
};

}  // namespace partita
