#include "diagnostics.hpp"

#include <algorithm>
#include <sstream>

namespace loam {

std::string Diagnostic::format() const {
  std::ostringstream s;
  s << (where.file.empty() ? "<input>" : where.file) << ':' << std::max(where.line, 1) << ':'
    << std::max(where.column, 1) << ": " << severity << ": " << (path.empty() ? "<document>" : path)
    << ": " << message;
  // One line per error, whatever it quotes: a key or value taken from the file may span lines
  // (a plain YAML scalar continued on the next lines), and its line breaks are shown as \n.
  std::string line;
  for (char c : s.str()) line += c == '\n' ? "\\n" : c == '\r' ? "\\r" : std::string(1, c);
  return line;
}

void Diagnostics::error(const Location& where, const std::string& path,
                        const std::string& message) {
  for (const auto& e : errors_)  // the same problem reached twice is reported once
    if (e.path == path && e.message == message) return;
  errors_.push_back({where, path, message});
}

namespace {

/// One line per diagnostic, in file order.
std::string format_sorted(std::vector<Diagnostic> sorted) {
  std::stable_sort(sorted.begin(), sorted.end(), [](const Diagnostic& a, const Diagnostic& b) {
    if (a.where.file != b.where.file) return a.where.file < b.where.file;
    if (a.where.line != b.where.line) return a.where.line < b.where.line;
    return a.where.column < b.where.column;
  });
  std::string out;
  for (const auto& e : sorted) out += e.format() + "\n";
  return out;
}

}  // namespace

std::string Diagnostics::format() const {
  return format_sorted(errors_);
}

void Diagnostics::warning(const Location& where, const std::string& path,
                          const std::string& message) {
  for (const auto& w : warnings_)
    if (w.path == path && w.message == message) return;
  warnings_.push_back({where, path, message, "warning"});
}

void Diagnostics::accept_warnings(const std::vector<std::string>& accepted) {
  std::erase_if(warnings_, [&](const Diagnostic& w) {
    return std::find(accepted.begin(), accepted.end(), w.path) != accepted.end();
  });
}

std::string Diagnostics::format_warnings() const {
  return format_sorted(warnings_);
}

int edit_distance(const std::string& a, const std::string& b) {
  std::vector<int> prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = int(j);
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = int(i);
    for (size_t j = 1; j <= b.size(); ++j) {
      int sub = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, sub});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string closest_match(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  int best_d = 1 << 30;
  for (const auto& c : candidates) {
    int d = edit_distance(word, c);
    if (d < best_d) best_d = d, best = c;
  }
  // Accept up to a third of the word length (at least 2 edits): catches typos, not guesses.
  int limit = std::max(2, int(word.size()) / 3);
  return best_d <= limit ? best : std::string();
}

std::string suggest(const std::string& word, const std::vector<std::string>& candidates,
                    const std::string& what) {
  std::string guess = closest_match(word, candidates);
  return (guess.empty() ? ";" : "; did you mean '" + guess + "'?") + " " + what + ": " +
         join(candidates, ", ");
}

std::string join(const std::vector<std::string>& items, const std::string& sep) {
  std::string out;
  for (size_t i = 0; i < items.size(); ++i) out += (i ? sep : "") + items[i];
  return out;
}

}  // namespace loam
