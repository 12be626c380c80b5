// Quantities with units in case files (config.hpp): parse_quantity and the units engineers write.
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
  static const std::vector<std::pair<std::string, double>> rate = {
      {"Hz", 1.0}, {"/s", 1.0}, {"s^-1", 1.0}};
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
  // a unit that starts with a digit ("40.4 1/s") is the unit, not a digit group
  const auto is_unit = [&](std::string_view t) {
    if (t == unit) return true;
    for (const auto& [name, factor] : equivalents(unit))
      if (t == name) return true;
    return false;
  };
  const bool space_group = !comma_group && rest.size() > after_space.size() && !after_space.empty() &&
                           std::isdigit(static_cast<unsigned char>(after_space[0])) &&
                           !is_unit(after_space);
  if (comma_group || space_group) {
    if (why) {
      std::string digits(text.substr(0, static_cast<std::size_t>(r.ptr - text.data())));
      // the groups: runs of digits and commas up to the unit (which may start with a digit)
      std::string_view r2 = comma_group ? rest : after_space;
      std::string groups;
      while (!r2.empty() && (std::isdigit(static_cast<unsigned char>(r2[0])) || r2[0] == ',') &&
             !is_unit(r2)) {
        std::size_t i = 0;
        for (; i < r2.size() && (std::isdigit(static_cast<unsigned char>(r2[i])) || r2[i] == ',');
             ++i)
          if (r2[i] != ',') groups += r2[i];
        r2 = trim(r2.substr(i));
      }
      const std::string tail(r2);
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

}  // namespace partita::config
