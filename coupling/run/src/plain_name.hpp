#pragma once
// The rule for names that become folder or file names (case names, sweep labels): one place.

#include <algorithm>
#include <cctype>
#include <string>

#include "partita/interface/config.hpp"

namespace partita::run {

/// Letters, digits, '-', '_', '.', '+', not empty and not starting with '.': no '/', '\', no
/// spaces, quotes or '..', so the name stays inside the folder it is put in.
inline bool is_plain_name(const std::string& name) {
  const bool bad_char = std::any_of(name.begin(), name.end(), [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return !(std::isalnum(u) || c == '-' || c == '_' || c == '.' || c == '+');
  });
  return !(name.empty() || bad_char || name.front() == '.');
}

/// Fails at `n` unless `name` is a plain name; `what` names it in the message.
inline void check_plain_name(const config::Node& n, const std::string& name,
                             const std::string& what) {
  if (!is_plain_name(name))
    n.fail(what +
           " is used in folder and file names, so it must be a plain name: letters, digits, "
           "'-', '_', '.', '+', not starting with '.' (no '/', no spaces, no quotes); found '" +
           name + "'");
}

}  // namespace partita::run
