#pragma once
// Collects every configuration error before any work starts, each formatted as
// FILE:LINE:COL: error: key.path: message   (docs/architecture.md "Errors").
#include <string>
#include <vector>

namespace loam {

/// A position in an input file; line and column are 1-based (yaml-cpp marks are 0-based).
struct Location {
  std::string file;
  int line = 0;
  int column = 0;
  bool known() const { return line > 0; }
};

struct Diagnostic {
  Location where;
  std::string path;
  std::string message;
  std::string severity = "error";
  std::string format() const;
};

class Diagnostics {
 public:
  void error(const Location& where, const std::string& path, const std::string& message);
  bool ok() const { return errors_.empty(); }
  const std::vector<Diagnostic>& errors() const { return errors_; }
  /// All errors, one per line, in file order.
  std::string format() const;
  /// A legal value that is almost surely a slip (ParamSpec::plausible): reported as
  /// FILE:LINE:COL: warning: key.path: message, and the run goes on.
  void warning(const Location& where, const std::string& path, const std::string& message);
  const std::vector<Diagnostic>& warnings() const { return warnings_; }
  /// Drop the warnings whose key path is in `accepted` (the run file's accept_warnings).
  void accept_warnings(const std::vector<std::string>& accepted);
  /// All warnings, one per line, in file order.
  std::string format_warnings() const;

 private:
  std::vector<Diagnostic> errors_, warnings_;
};

/// Thrown after validation when Diagnostics holds errors (exit code 2).
struct ConfigError {
  std::string text;
};

/// Levenshtein distance, for "did you mean" suggestions.
int edit_distance(const std::string& a, const std::string& b);
/// Closest candidate within a sensible distance, or "" if none is close.
std::string closest_match(const std::string& word, const std::vector<std::string>& candidates);
/// The tail of an "unknown name" message: "; did you mean 'b'? <what>: a, b, c", or
/// "; <what>: a, b, c" when no candidate is close (what: e.g. "valid keys are").
std::string suggest(const std::string& word, const std::vector<std::string>& candidates,
                    const std::string& what);
std::string join(const std::vector<std::string>& items, const std::string& sep);

}  // namespace loam
