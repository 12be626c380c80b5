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

/// One documented output quantity. `name` may hold placeholders in angle brackets for a family
/// of names ("<mesh>.force_z": one per mesh; "<wall>.<face>.force_z", "particle.<id>.z");
/// quantity_matches() applies them.
struct QuantityDoc {
  std::string name;
  std::string unit;  ///< SI unit; empty for a pure number
  std::string doc;
};

/// Whether a reported quantity name is one that `d` documents: the text outside the
/// placeholders as it is, each "<x>" any non-empty text without '.' (up to the next '.').
inline bool quantity_matches(const QuantityDoc& d, std::string_view name) {
  std::string_view pattern = d.name;
  while (!pattern.empty()) {
    if (pattern.front() != '<') {  // literal text up to the next placeholder
      const std::size_t lit = std::min(pattern.find('<'), pattern.size());
      if (name.substr(0, lit) != pattern.substr(0, lit)) return false;
      pattern.remove_prefix(lit);
      name.remove_prefix(lit);
      continue;
    }
    const auto close = pattern.find('>');
    if (close == std::string_view::npos) return false;
    pattern.remove_prefix(close + 1);
    const std::size_t span = std::min(name.find('.'), name.size());  // one dot-free part
    if (span == 0) return false;
    name.remove_prefix(span);
  }
  return name.empty();
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
