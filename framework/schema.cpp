// Parameter specifications and schemas: building a Schema (Schema::real, Schema::vector, ...) and
// the text of a spec's type and range that messages and `loam plugins` print.
#include "params.hpp"

#include <cmath>
#include <sstream>

namespace loam {

std::string format_number(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  std::ostringstream s;
  s.precision(15);
  s << v;
  return s.str();
}

void check_box_corners(const Params& p, Diagnostics& d, int skip_axis) {
  const auto &lo = p.vec("min"), &hi = p.vec("max");
  for (size_t i = 0; i < lo.size() && i < hi.size(); ++i)
    if (int(i) != skip_axis && hi[i] <= lo[i]) {
      d.error(p.where("max"), p.path("max"), "max must exceed min along every axis");
      return;
    }
}

bool ParamSpec::has_range() const {
  return std::isfinite(lo) || std::isfinite(hi);
}

// GCC 12 at -O3 reports a false -Wrestrict in the std::string operator+ inlined here; whether it
// does depends on what else the file holds (it did not while this was in params.cpp).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wrestrict"
std::string ParamSpec::range_text() const {
  return std::string(lo_open || !std::isfinite(lo) ? "(" : "[") + format_number(lo) + ", " +
         format_number(hi) + (hi_open || !std::isfinite(hi) ? ")" : "]");
}
#pragma GCC diagnostic pop

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

}  // namespace loam
