#include "partita/interface/error.hpp"

#include <algorithm>

namespace partita {

std::string SourceLocation::str() const {
  std::string s = file;
  if (line > 0) {
    s += ":" + std::to_string(line);
    if (column > 0) s += ":" + std::to_string(column);
  }
  return s;
}

namespace {
std::string located(const SourceLocation& where, const std::string& key_path,
                    const std::string& message) {
  std::string s;
  const std::string w = where.str();
  if (!w.empty()) s += w + ": ";
  if (!key_path.empty()) s += "key '" + key_path + "': ";
  return s + message;
}
}  // namespace

Error::Error(const std::string& message) : std::runtime_error(message), detail_(message) {}

Error::Error(const SourceLocation& where, const std::string& key_path, const std::string& message)
    : std::runtime_error(located(where, key_path, message)),
      where_(where),
      key_path_(key_path),
      detail_(message) {}

std::size_t edit_distance(std::string_view a, std::string_view b) {
  // Levenshtein distance, one row of the dynamic-programming table at a time.
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      const std::size_t cost = (a[i - 1] == b[j - 1]) ? 0 : 1;
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + cost});
      diag = up;
    }
  }
  return row[b.size()];
}

std::string nearest_name(std::string_view name, const std::vector<std::string>& known) {
  std::string best;
  std::size_t best_d = static_cast<std::size_t>(-1);
  for (const auto& k : known) {
    const std::size_t d = edit_distance(name, k);
    if (d < best_d) {
      best_d = d;
      best = k;
    }
  }
  const std::size_t limit = std::max<std::size_t>(2, std::max(name.size(), best.size()) / 3);
  if (!best.empty() && best_d <= limit) return best;
  // A name written short or long, a whole word of it kept: 'poisson' for 'poisson_ratio',
  // 'youngs' for 'youngs_modulus', 'friction_coefficient' for 'friction'. The shortest such.
  if (name.size() < 3) return "";
  auto word_prefix = [](std::string_view longer, std::string_view shorter) {
    return longer.size() > shorter.size() && longer.substr(0, shorter.size()) == shorter &&
           (longer[shorter.size()] == '_' || longer[shorter.size()] == '-');
  };
  best.clear();
  for (const auto& k : known)
    if ((word_prefix(k, name) || word_prefix(name, k)) && (best.empty() || k.size() < best.size()))
      best = k;
  return best;
}

std::string did_you_mean(std::string_view name, const std::vector<std::string>& known) {
  const std::string n = nearest_name(name, known);
  return n.empty() ? std::string() : "; did you mean '" + n + "'?";
}

std::string join_names(const std::vector<std::string>& names, std::string_view sep) {
  std::string s;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i) s += sep;
    s += names[i];
  }
  return s.empty() ? std::string("(none)") : s;
}

}  // namespace partita
