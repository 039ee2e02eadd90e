#pragma once
// Typed parameter specifications and validated parameter values.
// One Schema describes what a plugin (or a config section) accepts: type, unit, default or
// required, range or choices and a doc string. The same Schema validates YAML and generates
// `loam plugins` documentation, so the docs cannot drift from the checks (OpenFOAM/MOOSE habit).
#include <array>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <variant>
#include <vector>

#include "diagnostics.hpp"

namespace YAML {
class Node;
}

namespace loam {

enum class ParamType {
  Real,
  Integer,
  Boolean,
  String,
  Choice,
  Vector,      // fixed-length list of reals (length: dimension, components, or a number)
  RealList,    // any-length list of reals
  VectorList,  // list of vectors (e.g. polygon vertices)
  StringList,
  Section,  // nested map with its own schema
  SectionList,
  Plugin,  // map with `type:` naming a plugin of a kind; validated by that plugin's schema
  PluginList
};

/// Vector lengths that depend on the run.
constexpr int kDimension = 0;         // D components
constexpr int kFieldComponents = -1;  // the count the enclosing field asks for (velocity: D...)

class Schema;

struct ParamSpec {
  std::string key;
  ParamType type = ParamType::Real;
  std::string unit;  // SI unit, "-" for dimensionless
  std::string doc;
  bool is_required = false;
  std::string default_text;  // YAML text of the default, validated like user input
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false, hi_open = false;
  /// Plausible values: a legal nonzero value outside [plausible_lo, plausible_hi] is almost
  /// surely a unit slip and gets a located warning saying `plausible_hint`.
  double plausible_lo = -std::numeric_limits<double>::infinity();
  double plausible_hi = std::numeric_limits<double>::infinity();
  std::string plausible_hint;
  std::vector<std::string> choices;
  int length = kDimension;
  bool broadcast_scalar = false;  // a scalar stands for a vector with equal components
  std::shared_ptr<Schema> section;
  std::string plugin_kind;
  int plugin_components = kDimension;  // component count passed to a field plugin

  ParamSpec& required() {
    is_required = true;
    return *this;
  }
  ParamSpec& def(std::string yaml_text) {
    default_text = std::move(yaml_text);
    return *this;
  }
  ParamSpec& min(double v) {
    lo = v;
    lo_open = false;
    return *this;
  }
  ParamSpec& above(double v) {
    lo = v;
    lo_open = true;
    return *this;
  }
  ParamSpec& max(double v) {
    hi = v;
    hi_open = false;
    return *this;
  }
  ParamSpec& below(double v) {
    hi = v;
    hi_open = true;
    return *this;
  }
  ParamSpec& positive() { return above(0.0); }
  ParamSpec& plausible(double lo, double hi, std::string hint) {
    plausible_lo = lo;
    plausible_hi = hi;
    plausible_hint = std::move(hint);
    return *this;
  }
  bool has_plausible() const { return !plausible_hint.empty(); }
  ParamSpec& non_negative() { return min(0.0); }
  ParamSpec& len(int n) {
    length = n;
    return *this;
  }
  ParamSpec& scalar_ok() {
    broadcast_scalar = true;
    return *this;
  }
  ParamSpec& components(int n) {
    plugin_components = n;
    return *this;
  }

  bool has_range() const;
  std::string range_text() const;  // "(0, 0.5]" style
  std::string type_text() const;   // "real", "vector[D]", "plugin(material)", ...
};

class Params;
using Check = std::function<void(const Params&, Diagnostics&)>;

class Schema {
 public:
  ParamSpec& real(std::string key, std::string unit, std::string doc);
  ParamSpec& integer(std::string key, std::string doc);
  ParamSpec& boolean(std::string key, std::string doc);
  ParamSpec& text(std::string key, std::string doc);
  ParamSpec& choice(std::string key, std::vector<std::string> choices, std::string doc);
  ParamSpec& vector(std::string key, std::string unit, std::string doc, int length = kDimension);
  ParamSpec& real_list(std::string key, std::string unit, std::string doc);
  ParamSpec& vector_list(std::string key, std::string unit, std::string doc,
                         int length = kDimension);
  ParamSpec& string_list(std::string key, std::string doc);
  ParamSpec& section(std::string key, Schema schema, std::string doc);
  ParamSpec& section_list(std::string key, Schema schema, std::string doc);
  ParamSpec& plugin(std::string key, std::string kind, std::string doc);
  ParamSpec& plugin_list(std::string key, std::string kind, std::string doc);
  /// A rule across several parameters (e.g. psi <= phi); runs only if each key validated.
  void check(Check c) { checks.push_back(std::move(c)); }

  const ParamSpec* find(const std::string& key) const;
  std::vector<std::string> keys() const;

  std::vector<ParamSpec> params;
  std::vector<Check> checks;

 private:
  ParamSpec& add(std::string key, ParamType type, std::string unit, std::string doc);
};

/// Validated values of one map (a plugin's parameters or a config section).
class Params {
 public:
  using Value =
      std::variant<std::monostate, double, long long, bool, std::string, std::vector<double>,
                   std::vector<std::vector<double>>, std::vector<std::string>,
                   std::shared_ptr<Params>, std::vector<Params>>;
  struct Entry {
    Value value;
    Location where;
    bool defaulted = false;
    std::vector<Location> items;  // of each list element, when given as a list in the file
  };

  double real(const std::string& key) const;
  long long integer(const std::string& key) const;
  bool flag(const std::string& key) const;
  const std::string& text(const std::string& key) const;
  const std::vector<double>& vec(const std::string& key) const;
  const std::vector<std::vector<double>>& vecs(const std::string& key) const;
  const std::vector<std::string>& strings(const std::string& key) const;
  const Params& section(const std::string& key) const;
  const std::vector<Params>& list(const std::string& key) const;
  /// True when the key was given or has a default.
  bool has(const std::string& key) const;
  /// True when the key was given (not defaulted): e.g. an empty list given to replace another.
  bool given(const std::string& key) const;
  /// True when the key is in the file, even with a value that failed validation.
  bool present(const std::string& key) const;

  /// Plugin type name (for a Plugin map), empty otherwise.
  const std::string& type() const { return type_; }
  const std::string& path() const { return path_; }
  std::string path(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  const Location& where() const { return where_; }
  Location where(const std::string& key) const;
  /// Location of element `index` of a list value (the list's location if unknown).
  Location where(const std::string& key, size_t index) const;

  nlohmann::json to_json() const;

  // Construction (used by the validator and by code that builds configs).
  void set(const std::string& key, Value v, Location where, bool defaulted = false,
           std::vector<Location> items = {});
  void set_type(std::string t) { type_ = std::move(t); }
  void set_origin(std::string path, Location where) {
    path_ = std::move(path);
    where_ = std::move(where);
  }
  const std::vector<std::string>& keys() const { return order_; }

 private:
  const Entry& at(const std::string& key) const;
  std::map<std::string, Entry> values_;
  std::vector<std::string> order_;
  std::string type_, path_;
  Location where_;
};

/// What validation needs to know about the run.
struct ValidationContext {
  std::string file;
  int dimension = 2;
  int components = 2;  // for kFieldComponents
  /// Paths set with --set, mapped to a label used as their "file" in messages.
  std::map<std::string, std::string> overrides;
};

/// Validate `node` (a map) against `schema`. Errors go to `diag`; the result holds what was valid.
Params validate(const YAML::Node& node, const Schema& schema, const std::string& path,
                const Location& where, ValidationContext& ctx, Diagnostics& diag);

/// Validate a plugin map or name (`{type: linear, ...}` or `linear`) of `kind`.
Params validate_plugin(const YAML::Node& node, const std::string& kind, int components,
                       const std::string& path, const Location& where, ValidationContext& ctx,
                       Diagnostics& diag);

Location location_of(const YAML::Node& node, const std::string& path, const ValidationContext& ctx,
                     const Location& fallback);

/// Format a number the way users wrote it (shortest round-trip-ish form).
std::string format_number(double v);

/// A box for messages: "[x0, y0] to [x1, y1]".
template <size_t N>
std::string format_box(const std::array<double, N>& lo, const std::array<double, N>& hi) {
  std::string s = "[";
  for (size_t d = 0; d < N; ++d) s += (d ? ", " : "") + format_number(lo[d]);
  s += "] to [";
  for (size_t d = 0; d < N; ++d) s += (d ? ", " : "") + format_number(hi[d]);
  return s + "]";
}

/// The schema check of a box given by `min` and `max`: max > min along every axis (except
/// `skip_axis`, e.g. the normal of a face patch).
void check_box_corners(const Params& p, Diagnostics& d, int skip_axis = -1);

}  // namespace loam
