// A piecewise-linear table of (time, factor) points, inline (`times`, `values`) or from a CSV
// file of two columns (time, factor; a first line that is not numbers is a header; the path is
// relative to the run file's folder). Linear between points, the first value before the first
// time and the last after the last. The times must increase strictly.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "framework/diagnostics.hpp"
#include "framework/registry.hpp"
#include "framework/time_function.hpp"

namespace loam {

template <int D>
class TableTime : public TimeFunction<D> {
 public:
  static constexpr const char* name = "table";
  static constexpr const char* summary =
      "piecewise linear through (time, factor) points, inline or from a CSV file";
  static Schema schema() {
    Schema s;
    s.real_list("times", "s", "the points' times, strictly increasing (or give `file`)");
    s.real_list("values", "-", "the factor at each time");
    s.text("file",
           "a CSV file of two columns, time (s) and factor, one point a line (a header line is "
           "skipped); relative to the run file's folder");
    s.check([](const Params& p, Diagnostics& d) {
      std::vector<double> t, v;
      read(p, t, v, &d);
    });
    return s;
  }
  explicit TableTime(const Params& p) { read(p, t_, v_, nullptr); }

  double value(double t) const override {
    if (t <= t_.front()) return v_.front();
    if (t >= t_.back()) return v_.back();
    const size_t k = size_t(std::upper_bound(t_.begin(), t_.end(), t) - t_.begin());
    const double s = (t - t_[k - 1]) / (t_[k] - t_[k - 1]);
    return v_[k - 1] + s * (v_[k] - v_[k - 1]);
  }
  void kinks(double t0, double t1, std::vector<double>& out) const override {
    for (auto it = std::upper_bound(t_.begin(), t_.end(), t0); it != t_.end() && *it < t1; ++it)
      out.push_back(*it);
  }

 private:
  /// The points from the inline lists or the file; with `diag`, every problem as a located
  /// error (the schema's check), without it the points only (the constructor, after the check).
  static void read(const Params& p, std::vector<double>& t, std::vector<double>& v,
                   Diagnostics* diag) {
    auto error = [&](const std::string& key, const std::string& message) {
      if (!diag) return;
      if (key.empty())
        diag->error(p.where(), p.path(), message);
      else
        diag->error(p.where(key), p.path(key), message);
    };
    const bool inline_points = p.has("times") || p.has("values");
    if (inline_points == p.has("file")) {
      error("", "give either `times` and `values` or `file`");
      return;
    }
    std::string where = "times";
    if (p.has("file")) {
      where = "file";
      std::filesystem::path path = p.text("file");
      if (path.is_relative())
        path = std::filesystem::path(p.where("file").file).parent_path() / path;
      std::ifstream in(path);
      if (!in) {
        error("file", "cannot read '" + path.string() + "'");
        return;
      }
      std::string line;
      for (int n = 1; std::getline(in, line); ++n) {
        std::replace(line.begin(), line.end(), ',', ' ');
        std::istringstream words(line);
        double a, b;
        if (words >> a >> b) {
          t.push_back(a), v.push_back(b);
        } else if (n > 1 && line.find_first_not_of(" \t\r") != std::string::npos) {
          error("file", path.string() + ":" + std::to_string(n) + ": expected two numbers");
          return;
        }
      }
    } else {
      if (!p.has("times") || !p.has("values")) {
        error(p.has("times") ? "times" : "values", "give both `times` and `values`");
        return;
      }
      t = p.vec("times"), v = p.vec("values");
      if (t.size() != v.size()) {
        error("values", "give one value per time (" + std::to_string(t.size()) + " times, " +
                            std::to_string(v.size()) + " values)");
        return;
      }
    }
    if (t.size() < 2) {
      error(where, "give at least two points");
      return;
    }
    for (size_t k = 1; k < t.size(); ++k)
      if (!(t[k] > t[k - 1])) {
        error(where, "the times must increase strictly: point " + std::to_string(k + 1) +
                         " (t = " + format_number(t[k]) + ") is not after point " +
                         std::to_string(k) + " (t = " + format_number(t[k - 1]) + ")");
        return;
      }
  }

  std::vector<double> t_, v_;
};

LOAM_REGISTER(TimeFunction, TableTime)

}  // namespace loam
