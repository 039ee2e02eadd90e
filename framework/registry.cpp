#include "registry.hpp"

#include <dlfcn.h>

namespace loam {

Registry& Registry::instance() {
  static Registry registry;
  return registry;
}

void Registry::add_kind(const std::string& kind, const std::string& doc) {
  if (!has_kind(kind)) kinds_.push_back({kind, doc});
}

bool Registry::has_kind(const std::string& kind) const {
  for (const auto& k : kinds_)
    if (k.name == kind) return true;
  return false;
}

void Registry::add(PluginInfo info) {
  info.origin = loading_origin;
  auto& table = plugins_[info.kind];
  if (table.count(info.name))
    throw std::logic_error("plugin " + info.kind + " '" + info.name + "' registered twice");
  std::string name = info.name;
  table.emplace(name, std::move(info));
}

const PluginInfo* Registry::find(const std::string& kind, const std::string& name) const {
  auto k = plugins_.find(kind);
  if (k == plugins_.end()) return nullptr;
  auto p = k->second.find(name);
  return p == k->second.end() ? nullptr : &p->second;
}

std::vector<std::string> Registry::names(const std::string& kind) const {
  std::vector<std::string> out;
  auto k = plugins_.find(kind);
  if (k != plugins_.end())
    for (const auto& [name, info] : k->second) out.push_back(name);
  return out;
}

std::string Registry::default_of(const std::string& kind) const {
  auto it = defaults_.find(kind);
  return it == defaults_.end() ? "" : it->second;
}

std::string Registry::list_shorthand(const std::string& kind) const {
  auto it = shorthand_.find(kind);
  return it == shorthand_.end() ? "" : it->second;
}

std::string load_plugin_library(const std::string& path) {
  Registry& reg = Registry::instance();
  reg.loading_origin = path;
  void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_GLOBAL);
  reg.loading_origin = "built-in";
  if (!handle) return std::string("cannot load plugin library: ") + dlerror();
  using AbiFn = int (*)();
  auto abi = reinterpret_cast<AbiFn>(dlsym(handle, "loam_plugin_abi_version"));
  if (!abi) return "not a loam plugin library (no loam_plugin_abi_version symbol)";
  if (abi() != kPluginAbiVersion)
    return "plugin ABI version " + std::to_string(abi()) + " does not match loam's " +
           std::to_string(kPluginAbiVersion) + "; rebuild the plugin against this loam";
  return "";
}

}  // namespace loam
