#include "compare.hpp"

#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <numeric>
#include <regex>
#include <set>
#include <sstream>

#include "framework/diagnostics.hpp"
#include "framework/interrupt.hpp"
#include "framework/params.hpp"
#include "process.hpp"

namespace fs = std::filesystem;

namespace loam {

namespace {

struct Axis {
  std::string path;
  std::vector<std::string> values;
};

/// A metric of the sweep file's `metrics:` list: one number from a column of each variant's
/// history.csv or probe CSV, without a reference plugin (e.g. the peak of a reaction force).
struct UserMetric {
  std::string name, file, column, of;
  bool has_reference = false;
  double reference = 0;
};

struct Sweep {
  std::string file;
  fs::path base, out;
  std::vector<Axis> axes;
  std::vector<UserMetric> metrics;
  std::vector<std::string> fixed;  // overrides of every variant
  std::string metric, series;      // the plot's error column and series axis
  Location metric_at;
  int threads = 0;
};

struct Variant {
  std::vector<std::string> values;  // one per axis
  std::string name;                 // directory name
  std::string status, message;
  nlohmann::json summary;
  std::map<std::string, double> user;  // the sweep's own metrics
};

Schema metric_schema() {
  Schema s;
  s.text("name", "the metric's column in compare.csv").required();
  s.text("column", "a column of the variant's CSV (e.g. reaction_base_y)").required();
  s.text("file", "history (history.csv) or a probe's name (probe_NAME.csv)").def("history");
  s.choice("of", {"max", "min", "max_abs", "final", "mean"}, "what of the column").def("max_abs");
  s.real("reference", "-",
         "the value it should have: adds NAME_error = (value - reference) / |reference|");
  s.check([](const Params& m, Diagnostics& d) {
    if (m.has("reference") && m.real("reference") == 0)
      d.error(m.where("reference"), m.path("reference"),
              "a reference of 0 has no relative error; give the value it should have");
  });
  return s;
}

Schema sweep_schema() {
  Schema s;
  s.text("base", "run file the variants override (relative to the sweep file)").required();
  s.string_list("set", "overrides applied to every variant (path=value)");
  s.text("out", "output directory (default results/<sweep name>)");
  s.text("metric",
         "compare.csv column plotted as the error: a verify metric or one of `metrics` "
         "(default: the first verify metric named *error*)");
  s.text("series", "axis whose values are the plot's series (default: the first axis)");
  s.integer("threads", "threads per variant (default: all cores)").min(1);
  s.section_list("metrics", metric_schema(),
                 "metrics of the sweep's own from each variant's history or probe CSV");
  return s;
}

std::string sanitize(const std::string& s) {
  std::string out;
  for (char c : s)
    out += std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' ? c : '_';
  return out;
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return q + "\"";
}

bool load_summary(const fs::path& file, nlohmann::json& out) {
  std::ifstream in(file);
  if (!in) return false;
  try {
    out = nlohmann::json::parse(in);
    return out.contains("status");
  } catch (...) {
    return false;
  }
}

/// Every metric of a variant: the reference's verify numbers and the sweep's own.
std::map<std::string, double> metric_values(const Variant& v) {
  std::map<std::string, double> m = v.user;
  if (v.summary.contains("verify"))
    for (const auto& [k, x] : v.summary["verify"].items())
      if (x.is_number()) m[k] = x.get<double>();
  return m;
}

std::set<std::string> metric_names(const std::vector<Variant>& vs) {
  std::set<std::string> names;
  for (const auto& v : vs)
    for (const auto& [k, x] : metric_values(v)) names.insert(k);
  return names;
}

void write_csv(const fs::path& file, const std::vector<Axis>& axes,
               const std::vector<Variant>& vs) {
  const std::set<std::string> names = metric_names(vs);
  fs::path tmp = file;
  tmp += ".tmp";
  {
    std::ofstream o(tmp);
    o.precision(10);
    o << "variant";
    for (const auto& a : axes) o << "," << csv_field(a.path);
    o << ",status,wall_seconds,particle_steps_per_second,particles,steps,threads";
    for (const auto& m : names) o << "," << m;
    o << ",message\n";
    for (const auto& v : vs) {
      if (v.status.empty()) continue;  // not run yet
      o << v.name;
      for (const auto& x : v.values) o << "," << csv_field(x);
      o << "," << v.status;
      for (const char* k :
           {"wall_seconds", "particle_steps_per_second", "particles", "steps", "threads"}) {
        o << ",";
        if (v.summary.contains(k)) o << v.summary[k].dump();
      }
      const auto values = metric_values(v);
      for (const auto& m : names) {
        o << ",";
        if (values.count(m)) o << values.at(m);
      }
      o << "," << csv_field(v.message) << "\n";
    }
  }
  fs::rename(tmp, file);
}

/// The columns of a CSV with a header line, as numbers (a cell that is not one: NaN).
std::map<std::string, std::vector<double>> read_columns(const fs::path& file) {
  std::map<std::string, std::vector<double>> cols;
  std::ifstream in(file);
  std::string line;
  if (!std::getline(in, line)) return cols;
  std::vector<std::string> names;
  std::stringstream header(line);
  for (std::string name; std::getline(header, name, ',');) names.push_back(name);
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::string cell;
    for (size_t c = 0; c < names.size() && std::getline(row, cell, ','); ++c) {
      char* end = nullptr;
      const double x = std::strtod(cell.c_str(), &end);
      cols[names[c]].push_back(end != cell.c_str() ? x : std::nan(""));
    }
  }
  return cols;
}

/// `of` of a column's finite values (NaN when it has none).
double reduce_column(const std::vector<double>& xs, const std::string& of) {
  std::vector<double> f;
  for (double x : xs)
    if (std::isfinite(x)) f.push_back(x);
  if (f.empty()) return std::nan("");
  if (of == "final") return f.back();
  if (of == "mean") return std::accumulate(f.begin(), f.end(), 0.0) / double(f.size());
  if (of == "max") return *std::max_element(f.begin(), f.end());
  if (of == "min") return *std::min_element(f.begin(), f.end());
  double m = 0;
  for (double x : f) m = std::max(m, std::fabs(x));
  return m;
}

/// The sweep's own metrics of a variant from its output; a column it lacks is noted in its
/// message.
void measure_user_metrics(const Sweep& sweep, const fs::path& dir, Variant& v) {
  std::map<std::string, std::map<std::string, std::vector<double>>> read;  // each file once
  for (const UserMetric& m : sweep.metrics) {
    const std::string file = m.file == "history" ? "history.csv" : "probe_" + m.file + ".csv";
    if (!read.count(file)) read[file] = read_columns(dir / file);
    const auto& cols = read.at(file);
    if (!cols.count(m.column)) {
      if (v.status == "ok")
        v.message += (v.message.empty() ? "" : "; ") + std::string("metric ") + m.name + ": no " +
                     (cols.empty() ? file : "column " + m.column + " in " + file);
      continue;
    }
    const double x = reduce_column(cols.at(m.column), m.of);
    v.user[m.name] = x;
    if (m.has_reference) v.user[m.name + "_error"] = (x - m.reference) / std::fabs(m.reference);
  }
}

/// The sweep file's axes (arbitrary --set paths to lists, checked here rather than by a
/// schema) into `sweep.axes`.
void load_axes(const YAML::Node& root, const ValidationContext& ctx, Sweep& sweep,
               Diagnostics& diag) {
  YAML::Node axes = root.IsMap() ? root["axes"] : YAML::Node();
  if (!axes || !axes.IsMap() || axes.size() == 0) {
    diag.error(location_of(axes, "axes", ctx, Location{sweep.file, 1, 1}), "axes",
               "missing or empty 'axes' (a map of override paths to lists of values, e.g. "
               "'shape_function: [linear, gimp]')");
    return;
  }
  for (auto it = axes.begin(); it != axes.end(); ++it) {
    Axis a;
    a.path = it->first.Scalar();
    const YAML::Node values = it->second;
    Location loc = location_of(values, "axes." + a.path, ctx, Location{sweep.file, 1, 1});
    if (!values.IsSequence() || values.size() == 0) {
      diag.error(loc, "axes." + a.path, "expected a non-empty list of values");
      continue;
    }
    for (const auto& v : values) {
      std::ostringstream text;
      text << YAML::Dump(v);  // keeps lists/maps as flow YAML for --set
      std::string t = text.str();
      std::replace(t.begin(), t.end(), '\n', ' ');
      a.values.push_back(t);
    }
    sweep.axes.push_back(std::move(a));
  }
}

/// The validated keys besides `axes` into `sweep`.
void load_keys(const Params& p, const CompareOptions& opt, Sweep& sweep, Diagnostics& diag) {
  sweep.base = fs::path(p.text("base"));
  if (sweep.base.is_relative()) sweep.base = fs::path(sweep.file).parent_path() / sweep.base;
  if (!fs::exists(sweep.base))
    diag.error(p.where("base"), "base", "base run file not found: " + sweep.base.string());
  sweep.out = !opt.out_dir.empty() ? fs::path(opt.out_dir)
              : p.has("out")       ? fs::path(p.text("out"))
                                   : fs::path("results") / fs::path(sweep.file).stem();
  sweep.threads = opt.threads > 0 ? opt.threads : p.has("threads") ? int(p.integer("threads")) : 0;
  if (p.has("set")) sweep.fixed = p.strings("set");
  if (p.has("metric")) sweep.metric = p.text("metric"), sweep.metric_at = p.where("metric");
  sweep.series = p.has("series") ? p.text("series") : sweep.axes.empty() ? "" : sweep.axes[0].path;
  if (!p.has("metrics")) return;
  const auto& list = p.list("metrics");
  for (size_t i = 0; i < list.size(); ++i) {
    const Params& m = list[i];
    UserMetric u{m.text("name"), m.text("file"), m.text("column"), m.text("of")};
    if ((u.has_reference = m.has("reference"))) u.reference = m.real("reference");
    sweep.metrics.push_back(u);
  }
}

/// Reads and validates the sweep file; false (with every error printed) for a bad one.
bool load_sweep(const CompareOptions& opt, Sweep& sweep) {
  Diagnostics diag;
  sweep.file = opt.sweep_file;
  YAML::Node root;
  std::ifstream in(sweep.file);
  if (!in) {
    diag.error(Location{sweep.file, 1, 1}, "", "cannot open the sweep file: no such file");
  } else {
    try {
      root = YAML::Load(in);
    } catch (const YAML::Exception& e) {
      diag.error(Location{sweep.file, e.mark.line + 1, e.mark.column + 1}, "",
                 "malformed YAML: " + e.msg);
    }
  }
  if (diag.ok()) {
    ValidationContext ctx;
    ctx.file = sweep.file;
    load_axes(root, ctx, sweep, diag);
    YAML::Node rest = YAML::LoadFile(sweep.file);  // a second parse: a clone loses the marks
    if (rest.IsMap()) rest.remove("axes");
    Params p = validate(rest, sweep_schema(), "", Location{sweep.file, 1, 1}, ctx, diag);
    if (diag.ok()) load_keys(p, opt, sweep, diag);
  }
  if (!diag.ok()) fputs(diag.format().c_str(), stderr);
  return diag.ok();
}

/// Every combination of the axes' values, the last axis varying fastest.
std::vector<Variant> all_variants(const std::vector<Axis>& axes) {
  std::vector<Variant> variants;
  std::vector<size_t> idx(axes.size(), 0);
  while (true) {
    Variant v;
    for (size_t a = 0; a < axes.size(); ++a) {
      v.values.push_back(axes[a].values[idx[a]]);
      v.name += (a ? "__" : "") + sanitize(axes[a].path) + "=" + sanitize(axes[a].values[idx[a]]);
    }
    variants.push_back(std::move(v));
    size_t a = axes.size();
    while (a > 0 && ++idx[a - 1] == axes[a - 1].values.size()) idx[--a] = 0;
    if (a == 0) return variants;
  }
}

/// The variant's status from `loam run`'s exit code; a failure's message recorded (an invalid
/// variant also in its summary.json, so that a re-run does not retry it).
void record_outcome(int code, const std::string& output, const fs::path& dir, Variant& v) {
  v.status = code == 0 ? "ok" : code == 2 ? "invalid" : code == 3 ? "unstable" : "error";
  if (code == 0) return;
  v.message = output.empty() ? "exit code " + std::to_string(code) : output;
  if (code == 2) {
    fs::create_directories(dir);
    nlohmann::json s{{"status", "invalid"}, {"failure", v.message}};
    std::ofstream(dir / "summary.json") << s.dump(2) << "\n";
    v.summary = s;
  } else if (v.summary.is_null()) {
    v.summary = nlohmann::json{{"status", v.status}};
  }
}

/// One progress line per variant: its metrics named *error*, or its whole failure message.
void report_variant(const std::string& label, const Variant& v) {
  if (v.status != "ok") {
    spdlog::warn("{}: {}:\n  {}", label, v.status,
                 std::regex_replace(v.message, std::regex("\n"), "\n  "));
    return;
  }
  std::string metrics;
  for (const auto& [k, x] : metric_values(v))
    if (k.find("error") != std::string::npos) metrics += " " + k + "=" + format_number(x);
  spdlog::info("{}: ok, {:.3g} s,{}{}", label, v.summary.value("wall_seconds", 0.0), metrics,
               v.message.empty() ? "" : " (" + v.message + ")");
}

/// Runs variant i (or takes its finished result); returns 128 + signal when interrupted.
int run_variant(const Sweep& sweep, const CompareOptions& opt, std::vector<Variant>& variants,
                size_t i) {
  Variant& v = variants[i];
  const fs::path dir = sweep.out / "variants" / v.name;
  const std::string label =
      "[" + std::to_string(i + 1) + "/" + std::to_string(variants.size()) + "] " + v.name;
  nlohmann::json previous;
  if (load_summary(dir / "summary.json", previous) &&
      previous.value("status", "") != "interrupted") {
    v.summary = previous;
    v.status = previous["status"].get<std::string>();
    if (previous.contains("failure")) v.message = previous["failure"].get<std::string>();
    measure_user_metrics(sweep, dir, v);
    if (!opt.quiet) spdlog::info("{}: already done ({}), skipped", label, v.status);
    return 0;
  }
  const std::string exe = fs::read_symlink("/proc/self/exe").string();
  std::string cmd = shell_quote(exe) + " run " + shell_quote(sweep.base.string()) +
                    " --quiet --overwrite --out " + shell_quote(dir.string());
  if (sweep.threads > 0) cmd += " --threads " + std::to_string(sweep.threads);
  for (const auto& s : sweep.fixed) cmd += " --set " + shell_quote(s);
  for (size_t a = 0; a < sweep.axes.size(); ++a)
    cmd += " --set " + shell_quote(sweep.axes[a].path + "=" + v.values[a]);
  std::string output;
  const int code = run_command(cmd, output);
  while (!output.empty() && output.back() == '\n') output.pop_back();
  load_summary(dir / "summary.json", v.summary);
  if (code == 130 || code == 143 || InterruptGuard::requested()) {
    const int signal = InterruptGuard::requested() ? InterruptGuard::requested() : code - 128;
    v.status = "interrupted";
    v.message = output;
    spdlog::warn(
        "{}: interrupted by {}; compare.csv has the variants done so far; the same "
        "command resumes the sweep (the interrupted variant runs again)",
        label, signal_name(signal));
    return 128 + signal;
  }
  record_outcome(code, output, dir, v);
  measure_user_metrics(sweep, dir, v);
  if (!opt.quiet) report_variant(label, v);
  return 0;
}

/// The column plotted as the error: the sweep's `metric`, else the first metric named *error*;
/// empty (with the reason) when there is none.
std::string plot_metric(const Sweep& sweep, const std::vector<Variant>& variants,
                        std::string& why) {
  const std::set<std::string> names = metric_names(variants);
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
  if (!sweep.metric.empty()) {
    if (names.count(sweep.metric)) return sweep.metric;
    const Location& at = sweep.metric_at;
    why = at.file + ":" + std::to_string(at.line) + ":" + std::to_string(at.column) +
          ": metric: '" + sweep.metric + "' is not a metric of any variant (" +
          (list.empty() ? "none has one" : list) + ")";
    return "";
  }
  for (const auto& n : names)
    if (n.find("error") != std::string::npos) return n;
  why = "no metric named *error* (" + (list.empty() ? "the variants have none" : list) +
        "): name the column to plot with `metric:` in " + sweep.file +
        ", or define one under `metrics:` with a `reference`";
  return "";
}

/// pareto.png from compare.csv (tools/pareto.py); the CSV is the result, the figure optional.
void draw_pareto(const Sweep& sweep, const CompareOptions& opt,
                 const std::vector<Variant>& variants) {
  std::string why;
  const std::string metric = plot_metric(sweep, variants, why);
  if (metric.empty()) return spdlog::warn("pareto.png not written: {}", why);
  const std::string cmd = python_interpreter() + " " +
                          shell_quote(std::string(LOAM_TOOLS_DIR) + "/pareto.py") + " " +
                          shell_quote((sweep.out / "compare.csv").string()) + " --out " +
                          shell_quote((sweep.out / "pareto.png").string()) + " --series " +
                          shell_quote(sweep.series) + " --metric " + shell_quote(metric);
  std::string output;
  const int code = run_command(cmd, output);
  while (!output.empty() && output.back() == '\n') output.pop_back();
  if (code == 0) {
    if (!opt.quiet)
      spdlog::info("wrote {}{}", (sweep.out / "pareto.png").string(),
                   output.empty() ? "" : ": " + output);
  } else if (output.find("No module named") != std::string::npos) {
    spdlog::warn(
        "pareto.png not written: {} lacks matplotlib (Debian python3-matplotlib; "
        "tools/setup.sh installs it): {}",
        python_interpreter(), output);
  } else {
    spdlog::warn("pareto.png not written: {}", output);
  }
}

}  // namespace

int run_compare(const CompareOptions& opt) {
  Sweep sweep;
  if (!load_sweep(opt, sweep)) return 2;
  fs::create_directories(sweep.out / "variants");
  std::vector<Variant> variants = all_variants(sweep.axes);
  // SIGINT / SIGTERM (Ctrl-C reaches the running variant too, which stops cleanly with status
  // interrupted): the sweep stops after that variant, writes compare.csv and exits 128 +
  // signal; the same command later resumes it, re-running the interrupted variant.
  InterruptGuard guard;
  for (size_t i = 0; i < variants.size(); ++i) {
    const int interrupted = run_variant(sweep, opt, variants, i);
    write_csv(sweep.out / "compare.csv", sweep.axes, variants);
    if (interrupted) return interrupted;
  }
  if (!opt.quiet) spdlog::info("wrote {}", (sweep.out / "compare.csv").string());
  draw_pareto(sweep, opt, variants);
  return 0;
}

}  // namespace loam
