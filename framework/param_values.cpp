// Validated parameter values (Params): typed reads, where each value and list element was given,
// and the JSON form written to summary.json.
#include "params.hpp"

#include <nlohmann/json.hpp>

namespace loam {

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
bool Params::given(const std::string& k) const {
  auto it = values_.find(k);
  return has(k) && !it->second.defaulted;
}
bool Params::present(const std::string& k) const {
  auto it = values_.find(k);
  return it != values_.end() && !it->second.defaulted;
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

}  // namespace loam
