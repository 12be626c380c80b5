#pragma once
// The project's error type for user errors (bad input, divergence, unknown names).
// Programmer errors are asserts. `main` prints Error::what() and exits non-zero.

#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace partita {

/// Where in an input file something was found (1-based line and column; 0 = unknown).
struct SourceLocation {
  std::string file;
  int line = 0;
  int column = 0;
  /// "file:line:column" (parts that are unknown are left out).
  std::string str() const;
};

/// A user error. The message states the rule, the value found and the fix.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message);
  /// An error about one key of an input file: "file:line:col: key 'a.b.c': message".
  Error(const SourceLocation& where, const std::string& key_path, const std::string& message);

  const SourceLocation& where() const { return where_; }
  const std::string& key_path() const { return key_path_; }
  /// The message without the location prefix.
  const std::string& detail() const { return detail_; }

 private:
  SourceLocation where_;
  std::string key_path_;
  std::string detail_;
};

/// Levenshtein edit distance (for "did you mean").
std::size_t edit_distance(std::string_view a, std::string_view b);

/// The known name closest to `name`, or "" when none is plausibly meant
/// (distance larger than about a third of the length).
std::string nearest_name(std::string_view name, const std::vector<std::string>& known);

/// "; did you mean 'x'?" or "" (ready to append to a message).
std::string did_you_mean(std::string_view name, const std::vector<std::string>& known);

/// "a, b, c" — the names joined for a message.
std::string join_names(const std::vector<std::string>& names, std::string_view sep = ", ");

}  // namespace partita
