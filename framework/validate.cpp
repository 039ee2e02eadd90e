// YAML validation against a Schema: types, ranges, choices, unknown and missing keys, defaults,
// plugin maps and shorthands; every error located at FILE:LINE:COL (location_of).
#include "params.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>

#include "registry.hpp"

namespace loam {

Location location_of(const YAML::Node& node, const std::string& path, const ValidationContext& ctx,
                     const Location& fallback) {
  // Values given with --set have no place in the file: name the override instead.
  for (const auto& [p, label] : ctx.overrides)
    if (path == p || path.rfind(p + ".", 0) == 0) return Location{label, 1, 1};
  if (!node.IsDefined() || node.Mark().line < 0) return fallback;
  return Location{ctx.file, node.Mark().line + 1, node.Mark().column + 1};
}

namespace {

std::string node_text(const YAML::Node& n) {
  if (n.IsScalar()) return "'" + n.Scalar() + "'";
  if (n.IsSequence()) return "a list";
  if (n.IsMap()) return "a map";
  return "nothing";
}

struct Validator {
  ValidationContext& ctx;
  Diagnostics& diag;

  int resolve_length(int length) const {
    if (length == kDimension) return ctx.dimension;
    if (length == kFieldComponents) return ctx.components;
    return length;
  }

  bool parse_real(const YAML::Node& n, const std::string& path, const Location& loc, double& out) {
    if (n.IsScalar()) {
      const std::string& s = n.Scalar();
      char* end = nullptr;
      out = std::strtod(s.c_str(), &end);
      if (!s.empty() && end && *end == '\0' && std::isfinite(out)) return true;
    }
    diag.error(loc, path, "expected a real number, got " + node_text(n));
    return false;
  }

  bool in_range(const ParamSpec& spec, double v, const std::string& path, const Location& loc) {
    bool ok =
        (spec.lo_open ? v > spec.lo : v >= spec.lo) && (spec.hi_open ? v < spec.hi : v <= spec.hi);
    if (!ok)
      diag.error(loc, path,
                 format_number(v) + " is out of range " + spec.range_text() +
                     (spec.unit.empty() || spec.unit == "-" ? "" : " " + spec.unit));
    return ok;
  }

  /// A legal nonzero value outside the plausible range (ParamSpec::plausible): a warning.
  void warn_if_implausible(const ParamSpec& spec, double v, const std::string& path,
                           const Location& loc) {
    if (!spec.has_plausible() || v == 0 || (v >= spec.plausible_lo && v <= spec.plausible_hi))
      return;
    const std::string unit = spec.unit.empty() || spec.unit == "-" ? "" : " " + spec.unit;
    diag.warning(loc, path,
                 format_number(v) + unit + " is outside the plausible [" +
                     format_number(spec.plausible_lo) + ", " + format_number(spec.plausible_hi) +
                     "]" + unit + ": " + spec.plausible_hint +
                     " (list the key under accept_warnings: if it is meant)");
  }

  /// Each element of the sequence n parsed by parse(node, path, location, value); every bad
  /// element is reported. True when all parsed (then `out` holds them in order).
  template <class T, class Parse>
  bool parse_elements(const YAML::Node& n, const std::string& path, const Location& loc,
                      std::vector<T>& out, Parse&& parse) {
    bool ok = true;
    out.clear();
    for (size_t i = 0; i < n.size(); ++i) {
      T v{};
      const std::string p = path + "." + std::to_string(i);
      if (parse(n[i], p, location_of(n[i], p, ctx, loc), v))
        out.push_back(std::move(v));
      else
        ok = false;
    }
    return ok;
  }
  /// An element parser: a real number within spec's bounds.
  auto real_in_range(const ParamSpec& spec) {
    return [this, &spec](const YAML::Node& e, const std::string& p, const Location& l, double& v) {
      return parse_real(e, p, l, v) && in_range(spec, v, p, l);
    };
  }

  bool parse_vector(const ParamSpec& spec, const YAML::Node& n, const std::string& path,
                    const Location& loc, std::vector<double>& out) {
    int want = resolve_length(spec.length);
    if (spec.broadcast_scalar && n.IsScalar()) {
      double v;
      if (!parse_real(n, path, loc, v) || !in_range(spec, v, path, loc)) return false;
      out.assign(size_t(want), v);
      return true;
    }
    if (!n.IsSequence()) {
      diag.error(loc, path,
                 "expected a list of " + std::to_string(want) + " real numbers" +
                     (spec.broadcast_scalar ? " or one real number" : "") + ", got " +
                     node_text(n));
      return false;
    }
    if (want > 0 && int(n.size()) != want) {
      diag.error(
          loc, path,
          "expected " + std::to_string(want) + " components" +
              (spec.length == kDimension ? " (the grid is " + std::to_string(ctx.dimension) + "D)"
                                         : "") +
              ", got " + std::to_string(n.size()));
      return false;
    }
    return parse_elements(n, path, loc, out, real_in_range(spec));
  }

  /// A key's value by its type: one scalar, a list, or a nested map or plugin.
  Params::Value value(const ParamSpec& spec, const YAML::Node& n, const std::string& path,
                      const Location& loc) {
    switch (spec.type) {
      case ParamType::Real:
      case ParamType::Integer:
      case ParamType::Boolean:
      case ParamType::String:
      case ParamType::Choice:
        return scalar_value(spec, n, path, loc);
      case ParamType::Vector:
      case ParamType::RealList:
      case ParamType::VectorList:
      case ParamType::StringList:
        return list_value(spec, n, path, loc);
      case ParamType::Section:
      case ParamType::SectionList:
      case ParamType::PluginList:
      case ParamType::Plugin:
        return nested_value(spec, n, path, loc);
    }
    return {};
  }

  /// A real, integer, boolean, string or choice.
  Params::Value scalar_value(const ParamSpec& spec, const YAML::Node& n, const std::string& path,
                             const Location& loc) {
    switch (spec.type) {
      case ParamType::Real: {
        double v;
        if (!parse_real(n, path, loc, v) || !in_range(spec, v, path, loc)) return {};
        warn_if_implausible(spec, v, path, loc);
        return v;
      }
      case ParamType::Integer: {
        if (n.IsScalar()) {
          const std::string& s = n.Scalar();
          char* end = nullptr;
          long long v = std::strtoll(s.c_str(), &end, 10);
          if (!s.empty() && *end == '\0') {
            if (in_range(spec, double(v), path, loc)) return v;
            return {};
          }
        }
        diag.error(loc, path, "expected an integer, got " + node_text(n));
        return {};
      }
      case ParamType::Boolean: {
        if (n.IsScalar()) {
          const std::string& s = n.Scalar();
          if (s == "true" || s == "yes" || s == "on") return true;
          if (s == "false" || s == "no" || s == "off") return false;
        }
        diag.error(loc, path, "expected true or false, got " + node_text(n));
        return {};
      }
      case ParamType::String:
        if (n.IsScalar()) return n.Scalar();
        diag.error(loc, path, "expected a string, got " + node_text(n));
        return {};
      case ParamType::Choice: {
        if (!n.IsScalar()) {
          diag.error(loc, path,
                     "expected one of " + join(spec.choices, ", ") + ", got " + node_text(n));
          return {};
        }
        for (const auto& c : spec.choices)
          if (c == n.Scalar()) return c;
        diag.error(loc, path,
                   "unknown value '" + n.Scalar() + "'" +
                       suggest(n.Scalar(), spec.choices, "valid values are"));
        return {};
      }
      default:
        return {};
    }
  }

  /// A vector, a list of reals, points or names.
  Params::Value list_value(const ParamSpec& spec, const YAML::Node& n, const std::string& path,
                           const Location& loc) {
    switch (spec.type) {
      case ParamType::Vector: {
        std::vector<double> v;
        if (parse_vector(spec, n, path, loc, v)) return v;
        return {};
      }
      case ParamType::RealList: {
        if (!n.IsSequence()) {
          diag.error(loc, path, "expected a list of real numbers, got " + node_text(n));
          return {};
        }
        std::vector<double> out;
        if (parse_elements(n, path, loc, out, real_in_range(spec))) return out;
        return {};
      }
      case ParamType::VectorList: {
        if (!n.IsSequence()) {
          diag.error(loc, path, "expected a list of points, got " + node_text(n));
          return {};
        }
        std::vector<std::vector<double>> out;
        auto point = [&](const YAML::Node& e, const std::string& p, const Location& l,
                         std::vector<double>& v) { return parse_vector(spec, e, p, l, v); };
        if (parse_elements(n, path, loc, out, point)) return out;
        return {};
      }
      case ParamType::StringList: {
        std::vector<std::string> out;
        if (n.IsScalar()) return std::vector<std::string>{n.Scalar()};
        if (!n.IsSequence()) {
          diag.error(loc, path, "expected a list of names, got " + node_text(n));
          return {};
        }
        auto name = [&](const YAML::Node& e, const std::string& p, const Location& l,
                        std::string& v) {
          if (e.IsScalar()) {
            v = e.Scalar();
            return true;
          }
          diag.error(l, p, "expected a name, got " + node_text(e));
          return false;
        };
        if (parse_elements(n, path, loc, out, name)) return out;
        return {};
      }
      default:
        return {};
    }
  }

  /// A section, a list of sections or plugins, or a plugin.
  Params::Value nested_value(const ParamSpec& spec, const YAML::Node& n, const std::string& path,
                             const Location& loc) {
    switch (spec.type) {
      case ParamType::Section:
        if (!n.IsMap() && !n.IsNull()) {
          diag.error(loc, path, "expected a map, got " + node_text(n));
          return {};
        }
        return std::make_shared<Params>(section(n, *spec.section, path, loc));
      case ParamType::SectionList:
      case ParamType::PluginList: {
        if (!n.IsSequence()) {
          if (n.IsNull()) return std::vector<Params>{};
          diag.error(loc, path, "expected a list, got " + node_text(n));
          return {};
        }
        std::vector<Params> out;
        for (size_t i = 0; i < n.size(); ++i) {
          std::string p = path + "." + std::to_string(i);
          Location l = location_of(n[i], p, ctx, loc);
          if (spec.type == ParamType::SectionList) {
            if (!n[i].IsMap()) {
              diag.error(l, p, "expected a map, got " + node_text(n[i]));
              continue;
            }
            out.push_back(section(n[i], *spec.section, p, l));
          } else {
            out.push_back(plugin(n[i], spec.plugin_kind, spec.plugin_components, p, l));
          }
        }
        return out;
      }
      case ParamType::Plugin: {
        // A map without `type:` takes the key's default plugin (e.g. `scheme: {update: usl}`).
        // The map itself is validated (not a copy with `type:` added: a copy has lost the
        // marks, and its errors would read FILE:1:1).
        return std::make_shared<Params>(
            plugin(n, spec.plugin_kind, spec.plugin_components, path, loc, spec.default_text));
      }
      default:
        return {};
    }
  }

  Params section(const YAML::Node& n, const Schema& schema, const std::string& path,
                 const Location& loc, const std::string& extra_key = "") {
    Params out;
    out.set_origin(path, loc);
    auto child = [&](const std::string& k) { return path.empty() ? k : path + "." + k; };
    if (n.IsMap()) {
      std::vector<std::string> known = schema.keys();
      for (auto it = n.begin(); it != n.end(); ++it) {
        std::string key = it->first.IsScalar() ? it->first.Scalar() : "?";
        if (key == extra_key || schema.find(key)) continue;
        diag.error(location_of(it->first, child(key), ctx, loc), child(key),
                   "unknown key '" + key + "'" +
                       (known.empty() ? " (this takes no parameters)"
                                      : suggest(key, known, "valid keys are")));
      }
    }
    bool all_valid = true;
    for (const auto& spec : schema.params) {
      YAML::Node v = n.IsMap() ? n[spec.key] : YAML::Node();
      std::string p = child(spec.key);
      if (v && !v.IsNull()) {
        Location l = location_of(v, p, ctx, loc);
        Params::Value val = value(spec, v, p, l);
        if (std::holds_alternative<std::monostate>(val)) all_valid = false;
        std::vector<Location> items;  // for checks of list elements after validation
        if (v.IsSequence())
          for (size_t i = 0; i < v.size(); ++i)
            items.push_back(location_of(v[i], p + "." + std::to_string(i), ctx, l));
        out.set(spec.key, std::move(val), l, false, std::move(items));
      } else if (!spec.default_text.empty()) {
        YAML::Node d = YAML::Load(spec.default_text);
        Diagnostics quiet;
        Validator inner{ctx, quiet};
        out.set(spec.key, inner.value(spec, d, p, loc), loc, true);
        if (!quiet.ok()) throw std::logic_error("invalid default for " + p + ": " + quiet.format());
      } else if (spec.is_required) {
        std::string what =
            spec.doc.empty()
                ? ""
                : " (" + spec.doc +
                      (spec.unit.empty() || spec.unit == "-" ? "" : ", " + spec.unit) + ")";
        diag.error(loc, p, "missing required key '" + spec.key + "'" + what);
        all_valid = false;
      } else if (spec.type == ParamType::SectionList || spec.type == ParamType::PluginList) {
        out.set(spec.key, std::vector<Params>{}, loc, true);
      } else if (spec.type == ParamType::Section) {
        out.set(spec.key, std::make_shared<Params>(section(YAML::Node(), *spec.section, p, loc)),
                loc, true);
      }
    }
    if (all_valid)
      for (const auto& check : schema.checks) check(out, diag);
    return out;
  }

  /// A plugin entry: a name, a map with `type:` (or without it, given a default_type), or a
  /// bare list for the kind's shorthand.
  Params plugin(const YAML::Node& n, const std::string& kind, int components,
                const std::string& path, const Location& loc,
                const std::string& default_type = "") {
    Params failed;
    failed.set_origin(path, loc);
    Registry& reg = Registry::instance();
    std::string name;
    Location type_loc = loc;
    std::string type_path = path + ".type";
    if (n.IsScalar()) {
      name = n.Scalar();
    } else if (n.IsSequence() && !reg.list_shorthand(kind).empty()) {
      // A bare list stands for the kind's shorthand plugin, e.g. for fields a constant value:
      // [0, -9.81] == {type: constant, value: [0, -9.81]}.
      YAML::Node m;
      m["type"] = reg.list_shorthand(kind);
      m["value"] = n;
      return plugin(m, kind, components, path, loc);
    } else if (n.IsMap()) {
      YAML::Node t = n["type"];
      if (!t && !default_type.empty()) {
        name = default_type;
      } else if (!t || !t.IsScalar()) {
        diag.error(loc, type_path,
                   "missing required key 'type' (a " + kind +
                       "; valid types are: " + join(reg.names(kind), ", ") + ")");
        return failed;
      } else {
        name = t.Scalar();
        type_loc = location_of(t, type_path, ctx, loc);
      }
    } else {
      diag.error(loc, path,
                 "expected a " + kind + " name or a map with 'type', got " + node_text(n));
      return failed;
    }
    const PluginInfo* info = reg.find(kind, name);
    if (!info) {
      auto names = reg.names(kind);
      diag.error(type_loc, n.IsScalar() ? path : type_path,
                 "unknown " + kind + " '" + name + "'" + suggest(name, names, "valid types are"));
      return failed;
    }
    int saved = ctx.components;
    ctx.components = components == kDimension ? ctx.dimension : components;
    Params out = section(n.IsMap() ? n : YAML::Node(), info->schema(), path, loc, "type");
    ctx.components = saved;
    out.set_type(name);
    return out;
  }
};

}  // namespace

Params validate(const YAML::Node& node, const Schema& schema, const std::string& path,
                const Location& where, ValidationContext& ctx, Diagnostics& diag) {
  Validator v{ctx, diag};
  if (!node.IsMap() && !node.IsNull()) {
    diag.error(where, path, "expected a map, got " + node_text(node));
    return Params();
  }
  return v.section(node, schema, path, where);
}

Params validate_plugin(const YAML::Node& node, const std::string& kind, int components,
                       const std::string& path, const Location& where, ValidationContext& ctx,
                       Diagnostics& diag) {
  Validator v{ctx, diag};
  return v.plugin(node, kind, components, path, where);
}

}  // namespace loam
