#pragma once
// A registry of named factories. Registration is explicit: a module offers a function
// `register_builtin(...)` with one add() line per entry; no static self-registration.
// An unknown name is an error in every build type, listing the known names and the nearest.

#include <algorithm>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "partita/interface/config.hpp"
#include "partita/interface/error.hpp"

namespace partita {

/// One documented output quantity. `name` may start with a placeholder in angle brackets for a
/// family of names ("<mesh>.force_z": one per mesh); quantity_matches() applies it.
struct QuantityDoc {
  std::string name;
  std::string unit;  ///< SI unit; empty for a pure number
  std::string doc;
};

/// Whether a reported quantity name is one that `d` documents ("<x>" matches any text but '.').
inline bool quantity_matches(const QuantityDoc& d, std::string_view name) {
  if (d.name.empty() || d.name.front() != '<') return d.name == name;
  const auto close = d.name.find('>');
  if (close == std::string::npos) return false;
  const std::string_view rest = std::string_view(d.name).substr(close + 1);
  if (name.size() <= rest.size() || name.substr(name.size() - rest.size()) != rest) return false;
  return name.substr(0, name.size() - rest.size()).find('.') == std::string_view::npos;
}

template <class Factory>
class Registry {
 public:
  struct Entry {
    std::string name;
    std::string doc;  ///< one line
    Factory factory;
    std::shared_ptr<const config::Spec> spec;  ///< its parameters (may be null)
    /// What it reports (a solver's monitor quantities), listed on its `partita docs` page.
    std::vector<QuantityDoc> quantities;
  };

  /// `kind` names what is registered ("solver", "mapper", ...) for messages.
  explicit Registry(std::string kind) : kind_(std::move(kind)) {}

  /// Add an entry; a duplicate name is an error.
  void add(std::string name, std::string doc, Factory factory,
           std::shared_ptr<const config::Spec> spec = nullptr,
           std::vector<QuantityDoc> quantities = {}) {
    if (contains(name)) throw Error(kind_ + " '" + name + "' is registered twice");
    entries_.push_back(Entry{std::move(name), std::move(doc), std::move(factory), std::move(spec),
                             std::move(quantities)});
  }

  bool contains(std::string_view name) const { return find(name) != nullptr; }

  const Entry* find(std::string_view name) const {
    for (const auto& e : entries_)
      if (e.name == name) return &e;
    return nullptr;
  }

  /// The entry, or partita::Error "unknown <kind> 'x'; known: a, b, c; did you mean 'a'?".
  const Entry& get(std::string_view name) const {
    if (const Entry* e = find(name)) return *e;
    throw Error(unknown_message(name));
  }

  /// Same, but the error points at a YAML node.
  const Entry& get(const config::Node& where) const {
    const std::string name = where.as_string();
    if (const Entry* e = find(name)) return *e;
    where.fail(unknown_message(name));
  }

  std::vector<std::string> names() const {
    std::vector<std::string> n;
    for (const auto& e : entries_) n.push_back(e.name);
    return n;
  }
  const std::vector<Entry>& entries() const { return entries_; }
  const std::string& kind() const { return kind_; }

  std::string unknown_message(std::string_view name) const {
    return "unknown " + kind_ + " '" + std::string(name) + "'; known " + kind_ +
           "s: " + join_names(names()) + did_you_mean(name, names());
  }

 private:
  std::string kind_;
  std::vector<Entry> entries_;
};

}  // namespace partita
