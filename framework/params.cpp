#include "params.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

#include "registry.hpp"

namespace loam {

// ---------------------------------------------------------------- spec and schema

std::string format_number(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  std::ostringstream s;
  s.precision(15);
  s << v;
  return s.str();
}

bool ParamSpec::has_range() const {
  return std::isfinite(lo) || std::isfinite(hi);
}

std::string ParamSpec::range_text() const {
  return std::string(lo_open || !std::isfinite(lo) ? "(" : "[") + format_number(lo) + ", " +
         format_number(hi) + (hi_open || !std::isfinite(hi) ? ")" : "]");
}

static std::string length_text(int length) {
  if (length == kDimension) return "D";
  if (length == kFieldComponents) return "n";
  return std::to_string(length);
}

std::string ParamSpec::type_text() const {
  switch (type) {
    case ParamType::Real:
      return "real";
    case ParamType::Integer:
      return "integer";
    case ParamType::Boolean:
      return "bool";
    case ParamType::String:
      return "string";
    case ParamType::Choice:
      return "one of {" + join(choices, ", ") + "}";
    case ParamType::Vector:
      return "vector[" + length_text(length) + "]" + (broadcast_scalar ? " or real" : "");
    case ParamType::RealList:
      return "list of reals";
    case ParamType::VectorList:
      return "list of vector[" + length_text(length) + "]";
    case ParamType::StringList:
      return "list of strings";
    case ParamType::Section:
      return "map";
    case ParamType::SectionList:
      return "list of maps";
    case ParamType::Plugin:
      return plugin_kind + " {type: ...}";
    case ParamType::PluginList:
      return "list of " + plugin_kind + " {type: ...}";
  }
  return "?";
}

ParamSpec& Schema::add(std::string key, ParamType type, std::string unit, std::string doc) {
  ParamSpec p;
  p.key = std::move(key);
  p.type = type;
  p.unit = std::move(unit);
  p.doc = std::move(doc);
  params.push_back(std::move(p));
  return params.back();
}

ParamSpec& Schema::real(std::string k, std::string unit, std::string doc) {
  return add(std::move(k), ParamType::Real, std::move(unit), std::move(doc));
}
ParamSpec& Schema::integer(std::string k, std::string doc) {
  return add(std::move(k), ParamType::Integer, "-", std::move(doc));
}
ParamSpec& Schema::boolean(std::string k, std::string doc) {
  return add(std::move(k), ParamType::Boolean, "-", std::move(doc));
}
ParamSpec& Schema::text(std::string k, std::string doc) {
  return add(std::move(k), ParamType::String, "-", std::move(doc));
}
ParamSpec& Schema::choice(std::string k, std::vector<std::string> c, std::string doc) {
  auto& p = add(std::move(k), ParamType::Choice, "-", std::move(doc));
  p.choices = std::move(c);
  return p;
}
ParamSpec& Schema::vector(std::string k, std::string unit, std::string doc, int length) {
  auto& p = add(std::move(k), ParamType::Vector, std::move(unit), std::move(doc));
  p.length = length;
  return p;
}
ParamSpec& Schema::real_list(std::string k, std::string unit, std::string doc) {
  return add(std::move(k), ParamType::RealList, std::move(unit), std::move(doc));
}
ParamSpec& Schema::vector_list(std::string k, std::string unit, std::string doc, int length) {
  auto& p = add(std::move(k), ParamType::VectorList, std::move(unit), std::move(doc));
  p.length = length;
  return p;
}
ParamSpec& Schema::string_list(std::string k, std::string doc) {
  return add(std::move(k), ParamType::StringList, "-", std::move(doc));
}
ParamSpec& Schema::section(std::string k, Schema s, std::string doc) {
  auto& p = add(std::move(k), ParamType::Section, "-", std::move(doc));
  p.section = std::make_shared<Schema>(std::move(s));
  return p;
}
ParamSpec& Schema::section_list(std::string k, Schema s, std::string doc) {
  auto& p = add(std::move(k), ParamType::SectionList, "-", std::move(doc));
  p.section = std::make_shared<Schema>(std::move(s));
  return p;
}
ParamSpec& Schema::plugin(std::string k, std::string kind, std::string doc) {
  auto& p = add(std::move(k), ParamType::Plugin, "-", std::move(doc));
  p.plugin_kind = std::move(kind);
  return p;
}
ParamSpec& Schema::plugin_list(std::string k, std::string kind, std::string doc) {
  auto& p = add(std::move(k), ParamType::PluginList, "-", std::move(doc));
  p.plugin_kind = std::move(kind);
  return p;
}

const ParamSpec* Schema::find(const std::string& key) const {
  for (const auto& p : params)
    if (p.key == key) return &p;
  return nullptr;
}

std::vector<std::string> Schema::keys() const {
  std::vector<std::string> k;
  for (const auto& p : params) k.push_back(p.key);
  return k;
}

// ---------------------------------------------------------------- values

const Params::Entry& Params::at(const std::string& key) const {
  auto it = values_.find(key);
  if (it == values_.end() || std::holds_alternative<std::monostate>(it->second.value))
    throw std::logic_error("parameter '" + path(key) + "' was not validated or has no value");
  return it->second;
}

template <class T>
static const T& get_as(const Params::Entry& e, const std::string& path) {
  if (auto* v = std::get_if<T>(&e.value)) return *v;
  throw std::logic_error("parameter '" + path + "' read with the wrong type");
}

double Params::real(const std::string& k) const {
  const auto& e = at(k);
  if (auto* i = std::get_if<long long>(&e.value)) return double(*i);
  return get_as<double>(e, path(k));
}
long long Params::integer(const std::string& k) const {
  return get_as<long long>(at(k), path(k));
}
bool Params::flag(const std::string& k) const {
  return get_as<bool>(at(k), path(k));
}
const std::string& Params::text(const std::string& k) const {
  return get_as<std::string>(at(k), path(k));
}
const std::vector<double>& Params::vec(const std::string& k) const {
  return get_as<std::vector<double>>(at(k), path(k));
}
const std::vector<std::vector<double>>& Params::vecs(const std::string& k) const {
  return get_as<std::vector<std::vector<double>>>(at(k), path(k));
}
const std::vector<std::string>& Params::strings(const std::string& k) const {
  return get_as<std::vector<std::string>>(at(k), path(k));
}
const Params& Params::section(const std::string& k) const {
  return *get_as<std::shared_ptr<Params>>(at(k), path(k));
}
const std::vector<Params>& Params::list(const std::string& k) const {
  return get_as<std::vector<Params>>(at(k), path(k));
}
bool Params::has(const std::string& k) const {
  auto it = values_.find(k);
  return it != values_.end() && !std::holds_alternative<std::monostate>(it->second.value);
}
Location Params::where(const std::string& k) const {
  auto it = values_.find(k);
  return it == values_.end() ? where_ : it->second.where;
}
Location Params::where(const std::string& k, size_t index) const {
  auto it = values_.find(k);
  if (it != values_.end() && index < it->second.items.size()) return it->second.items[index];
  return where(k);
}

void Params::set(const std::string& key, Value v, Location where, bool defaulted,
                 std::vector<Location> items) {
  if (!values_.count(key)) order_.push_back(key);
  values_[key] = Entry{std::move(v), std::move(where), defaulted, std::move(items)};
}

nlohmann::json Params::to_json() const {
  nlohmann::json j = nlohmann::json::object();
  if (!type_.empty()) j["type"] = type_;
  for (const auto& key : order_) {
    const Value& v = values_.at(key).value;
    std::visit(
        [&](const auto& x) {
          using T = std::decay_t<decltype(x)>;
          if constexpr (std::is_same_v<T, std::monostate>) {
          } else if constexpr (std::is_same_v<T, std::shared_ptr<Params>>) {
            j[key] = x->to_json();
          } else if constexpr (std::is_same_v<T, std::vector<Params>>) {
            j[key] = nlohmann::json::array();
            for (const auto& p : x) j[key].push_back(p.to_json());
          } else {
            j[key] = x;
          }
        },
        v);
  }
  return j;
}

// ---------------------------------------------------------------- validation

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
    bool ok = true;
    out.clear();
    for (size_t i = 0; i < n.size(); ++i) {
      double v = 0;
      std::string p = path + "." + std::to_string(i);
      Location l = location_of(n[i], p, ctx, loc);
      if (parse_real(n[i], p, l, v) && in_range(spec, v, p, l))
        out.push_back(v);
      else
        ok = false;
    }
    return ok;
  }

  Params::Value value(const ParamSpec& spec, const YAML::Node& n, const std::string& path,
                      const Location& loc) {
    switch (spec.type) {
      case ParamType::Real: {
        double v;
        if (parse_real(n, path, loc, v) && in_range(spec, v, path, loc)) return v;
        return {};
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
      case ParamType::Vector: {
        std::vector<double> v;
        if (parse_vector(spec, n, path, loc, v)) return v;
        return {};
      }
      case ParamType::RealList: {
        ParamSpec any = spec;
        any.length = -1000;  // any length
        if (!n.IsSequence()) {
          diag.error(loc, path, "expected a list of real numbers, got " + node_text(n));
          return {};
        }
        std::vector<double> out;
        bool ok = true;
        for (size_t i = 0; i < n.size(); ++i) {
          double v;
          std::string p = path + "." + std::to_string(i);
          Location l = location_of(n[i], p, ctx, loc);
          if (parse_real(n[i], p, l, v) && in_range(spec, v, p, l))
            out.push_back(v);
          else
            ok = false;
        }
        if (ok) return out;
        return {};
      }
      case ParamType::VectorList: {
        if (!n.IsSequence()) {
          diag.error(loc, path, "expected a list of points, got " + node_text(n));
          return {};
        }
        std::vector<std::vector<double>> out;
        bool ok = true;
        for (size_t i = 0; i < n.size(); ++i) {
          std::vector<double> v;
          std::string p = path + "." + std::to_string(i);
          if (parse_vector(spec, n[i], p, location_of(n[i], p, ctx, loc), v))
            out.push_back(v);
          else
            ok = false;
        }
        if (ok) return out;
        return {};
      }
      case ParamType::StringList: {
        std::vector<std::string> out;
        if (n.IsScalar()) return std::vector<std::string>{n.Scalar()};
        if (!n.IsSequence()) {
          diag.error(loc, path, "expected a list of names, got " + node_text(n));
          return {};
        }
        bool ok = true;
        for (size_t i = 0; i < n.size(); ++i) {
          std::string p = path + "." + std::to_string(i);
          if (n[i].IsScalar())
            out.push_back(n[i].Scalar());
          else {
            diag.error(location_of(n[i], p, ctx, loc), p,
                       "expected a name, got " + node_text(n[i]));
            ok = false;
          }
        }
        if (ok) return out;
        return {};
      }
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
        if (n.IsMap() && !n["type"] && !spec.default_text.empty()) {
          YAML::Node copy = YAML::Clone(n);
          copy["type"] = spec.default_text;
          return std::make_shared<Params>(
              plugin(copy, spec.plugin_kind, spec.plugin_components, path, loc));
        }
        return std::make_shared<Params>(
            plugin(n, spec.plugin_kind, spec.plugin_components, path, loc));
      }
    }
    return {};
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

  Params plugin(const YAML::Node& n, const std::string& kind, int components,
                const std::string& path, const Location& loc) {
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
      if (!t || !t.IsScalar()) {
        diag.error(loc, type_path,
                   "missing required key 'type' (a " + kind +
                       "; valid types are: " + join(reg.names(kind), ", ") + ")");
        return failed;
      }
      name = t.Scalar();
      type_loc = location_of(t, type_path, ctx, loc);
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
