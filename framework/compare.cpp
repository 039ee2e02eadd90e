#include "compare.hpp"

#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "diagnostics.hpp"
#include "interrupt.hpp"
#include "params.hpp"
#include "process.hpp"

namespace fs = std::filesystem;

namespace loam {

namespace {

struct Axis {
  std::string path;
  std::vector<std::string> values;
};

struct Variant {
  std::vector<std::string> values;  // one per axis
  std::string name;                 // directory name
  std::string status, message;
  nlohmann::json summary;
};

Schema sweep_schema() {
  Schema s;
  s.text("base", "run file the variants override (relative to the sweep file)").required();
  s.string_list("set", "overrides applied to every variant (path=value)");
  s.text("out", "output directory (default results/<sweep name>)");
  s.text("metric", "verify metric plotted as the error (default: the first one named *error*)");
  s.text("series", "axis whose values are the plot's series (default: the first axis)");
  s.integer("threads", "threads per variant (default: all cores)").min(1);
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

void write_csv(const fs::path& file, const std::vector<Axis>& axes,
               const std::vector<Variant>& vs) {
  std::set<std::string> metric_names;
  for (const auto& v : vs)
    if (v.summary.contains("verify"))
      for (const auto& [k, x] : v.summary["verify"].items())
        if (x.is_number()) metric_names.insert(k);
  fs::path tmp = file;
  tmp += ".tmp";
  {
    std::ofstream o(tmp);
    o.precision(10);
    o << "variant";
    for (const auto& a : axes) o << "," << csv_field(a.path);
    o << ",status,wall_seconds,particle_steps_per_second,particles,steps,threads";
    for (const auto& m : metric_names) o << "," << m;
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
      for (const auto& m : metric_names) {
        o << ",";
        if (v.summary.contains("verify") && v.summary["verify"].contains(m) &&
            v.summary["verify"][m].is_number())
          o << v.summary["verify"][m].get<double>();
      }
      o << "," << csv_field(v.message) << "\n";
    }
  }
  fs::rename(tmp, file);
}

}  // namespace

int run_compare(const CompareOptions& opt) {
  Diagnostics diag;
  const std::string& file = opt.sweep_file;
  YAML::Node root;
  {
    std::ifstream in(file);
    if (!in) {
      diag.error(Location{file, 1, 1}, "", "cannot open the sweep file: no such file");
      fputs(diag.format().c_str(), stderr);
      return 2;
    }
    try {
      root = YAML::Load(in);
    } catch (const YAML::Exception& e) {
      diag.error(Location{file, e.mark.line + 1, e.mark.column + 1}, "",
                 "malformed YAML: " + e.msg);
      fputs(diag.format().c_str(), stderr);
      return 2;
    }
  }
  ValidationContext ctx;
  ctx.file = file;
  // `axes` maps arbitrary --set paths to lists, so it is checked here rather than by a schema.
  std::vector<Axis> axes;
  YAML::Node axes_node = root.IsMap() ? root["axes"] : YAML::Node();
  if (!axes_node || !axes_node.IsMap() || axes_node.size() == 0) {
    diag.error(location_of(axes_node, "axes", ctx, Location{file, 1, 1}), "axes",
               "missing or empty 'axes' (a map of override paths to lists of values, e.g. "
               "'shape_function: [linear, gimp]')");
  } else {
    for (auto it = axes_node.begin(); it != axes_node.end(); ++it) {
      Axis a;
      a.path = it->first.Scalar();
      Location loc = location_of(it->second, "axes." + a.path, ctx, Location{file, 1, 1});
      if (!it->second.IsSequence() || it->second.size() == 0) {
        diag.error(loc, "axes." + a.path, "expected a non-empty list of values");
        continue;
      }
      for (const auto& v : it->second) {
        std::ostringstream s;
        s << YAML::Dump(v);  // keeps lists/maps as flow YAML for --set
        std::string text = s.str();
        std::replace(text.begin(), text.end(), '\n', ' ');
        a.values.push_back(text);
      }
      axes.push_back(std::move(a));
    }
  }
  YAML::Node rest = YAML::Clone(root);
  if (rest.IsMap()) rest.remove("axes");
  Params p = validate(rest, sweep_schema(), "", Location{file, 1, 1}, ctx, diag);
  fs::path base;
  if (diag.ok()) {
    base = fs::path(p.text("base"));
    if (base.is_relative()) base = fs::path(file).parent_path() / base;
    if (!fs::exists(base))
      diag.error(p.where("base"), "base", "base run file not found: " + base.string());
  }
  if (!diag.ok()) {
    fputs(diag.format().c_str(), stderr);
    return 2;
  }
  fs::path out = !opt.out_dir.empty() ? fs::path(opt.out_dir)
                 : p.has("out")       ? fs::path(p.text("out"))
                                      : fs::path("results") / fs::path(file).stem();
  fs::create_directories(out / "variants");
  const int threads = opt.threads > 0    ? opt.threads
                      : p.has("threads") ? int(p.integer("threads"))
                                         : 0;
  std::vector<std::string> fixed = p.has("set") ? p.strings("set") : std::vector<std::string>{};

  // Every combination, the last axis varying fastest.
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
    if (a == 0) break;
  }

  const std::string exe = fs::read_symlink("/proc/self/exe").string();
  // SIGINT / SIGTERM (Ctrl-C reaches the running variant too, which stops cleanly with status
  // interrupted): the sweep stops after that variant, writes compare.csv and exits 128 +
  // signal; the same command later resumes it, re-running the interrupted variant.
  InterruptGuard guard;
  int interrupted = 0;
  for (size_t i = 0; i < variants.size(); ++i) {
    Variant& v = variants[i];
    fs::path dir = out / "variants" / v.name;
    std::string label =
        "[" + std::to_string(i + 1) + "/" + std::to_string(variants.size()) + "] " + v.name;
    nlohmann::json previous;
    if (load_summary(dir / "summary.json", previous) &&
        previous.value("status", "") != "interrupted") {
      v.summary = previous;
      v.status = previous["status"].get<std::string>();
      if (previous.contains("failure")) v.message = previous["failure"].get<std::string>();
      if (!opt.quiet) spdlog::info("{}: already done ({}), skipped", label, v.status);
      continue;
    }
    std::string cmd = shell_quote(exe) + " run " + shell_quote(base.string()) +
                      " --quiet --overwrite --out " + shell_quote(dir.string());
    if (threads > 0) cmd += " --threads " + std::to_string(threads);
    for (const auto& s : fixed) cmd += " --set " + shell_quote(s);
    for (size_t a = 0; a < axes.size(); ++a)
      cmd += " --set " + shell_quote(axes[a].path + "=" + v.values[a]);
    std::string output;
    int code = run_command(cmd, output);
    while (!output.empty() && output.back() == '\n') output.pop_back();
    load_summary(dir / "summary.json", v.summary);
    if (code == 130 || code == 143 || InterruptGuard::requested()) {
      interrupted = InterruptGuard::requested() ? InterruptGuard::requested() : code - 128;
      v.status = "interrupted";
      v.message = output;
      write_csv(out / "compare.csv", axes, variants);
      spdlog::warn(
          "{}: interrupted by {}; compare.csv has the variants done so far; the same "
          "command resumes the sweep (the interrupted variant runs again)",
          label, signal_name(interrupted));
      return 128 + interrupted;
    }
    v.status = code == 0 ? "ok" : code == 2 ? "invalid" : code == 3 ? "unstable" : "error";
    if (code != 0) {
      v.message = output.empty() ? "exit code " + std::to_string(code) : output;
      if (code == 2) {
        // Record the failure so a re-run does not retry an invalid variant.
        fs::create_directories(dir);
        nlohmann::json s{{"status", "invalid"}, {"failure", v.message}};
        std::ofstream(dir / "summary.json") << s.dump(2) << "\n";
        v.summary = s;
      } else if (v.summary.is_null()) {
        v.summary = nlohmann::json{{"status", v.status}};
      }
    }
    if (!opt.quiet) {
      std::string metrics;
      if (v.summary.contains("verify"))
        for (const auto& [k, x] : v.summary["verify"].items())
          if (x.is_number() && k.find("error") != std::string::npos)
            metrics += " " + k + "=" + format_number(x.get<double>());
      if (code == 0)
        spdlog::info("{}: ok, {:.3g} s,{}", label, v.summary.value("wall_seconds", 0.0), metrics);
      else
        spdlog::warn("{}: {} ({})", label, v.status, v.message.substr(0, 200));
    }
    write_csv(out / "compare.csv", axes, variants);
  }
  write_csv(out / "compare.csv", axes, variants);
  if (!opt.quiet) spdlog::info("wrote {}", (out / "compare.csv").string());

  // The plot is optional: the CSV above is the result; the PNG needs python3 + matplotlib.
  std::string metric = p.has("metric") ? p.text("metric") : "";
  std::string series = p.has("series") ? p.text("series") : axes.empty() ? "" : axes[0].path;
  const std::string python = python_interpreter();
  std::string plot = python + " " + shell_quote(std::string(LOAM_TOOLS_DIR) + "/pareto.py") + " " +
                     shell_quote((out / "compare.csv").string()) + " --out " +
                     shell_quote((out / "pareto.png").string()) + " --series " +
                     shell_quote(series) +
                     (metric.empty() ? "" : " --metric " + shell_quote(metric));
  std::string plot_output;
  if (run_command(plot, plot_output) == 0) {
    if (!opt.quiet) spdlog::info("wrote {}", (out / "pareto.png").string());
  } else {
    spdlog::warn("pareto.png not written (python3 with matplotlib needed): {}", plot_output);
  }
  return 0;
}

}  // namespace loam
