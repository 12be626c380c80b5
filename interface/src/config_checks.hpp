#pragma once
// What the schema (config_spec.cpp) and the nodes (config.cpp) share inside the library.
#include <string>

#include "partita/interface/config.hpp"

namespace partita::config::detail {

// Whether the whole text is a number (from_chars).
bool is_number_text(const std::string& s);
// Checks of one value against its parameter declaration (shared by validate() and getters).
void check_value(const Node& c, const Param& p);

}  // namespace partita::config::detail
