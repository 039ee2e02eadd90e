#pragma once
// Run-time selection tables for every plugin kind (LAMMPS styles / OpenFOAM run-time selection).
// A plugin is a class template on the dimension D with
//   static constexpr const char* name;      // its YAML `type:` name
//   static constexpr const char* summary;   // one line for `loam plugins`
//   static Schema schema();                 // its parameters
//   explicit Plugin(const Params&);
// and registers itself with one line at the bottom of its own file:
//   LOAM_REGISTER(Material, LinearElastic);
// The registry lives in libloam (a shared library), so built-in registrations cannot be dropped
// by the linker and dlopen-ed plugins see the same tables.
#include <any>
#include <array>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "params.hpp"

namespace loam {

/// Bumped when a plugin base interface changes; out-of-tree plugins check it.
/// 2: Boundary::constrain_grid_update (all phases of a grid update, with nodal masses).
/// 3: Boundary::mark_held, coulomb_update and add_forces, GridUpdate::held (the passes of the
///    grid update), Scheme::add_energies.
/// 5: Boundary::save_state/restore_state (checkpointed conditions), GridForces::time and
///    GridUpdate::time.
constexpr int kPluginAbiVersion = 5;

struct PluginInfo {
  std::string kind, name, summary;
  std::function<Schema()> schema;
  std::array<std::any, 3>
      factories;  // [D-1]: std::function<std::unique_ptr<Base<D>>(const Params&)>
  std::string origin = "built-in";
};

struct KindInfo {
  std::string name, doc;
};

class Registry {
 public:
  static Registry& instance();

  void add_kind(const std::string& kind, const std::string& doc);
  void add(PluginInfo info);
  const PluginInfo* find(const std::string& kind, const std::string& name) const;
  std::vector<std::string> names(const std::string& kind) const;
  const std::vector<KindInfo>& kinds() const { return kinds_; }
  bool has_kind(const std::string& kind) const;

  template <template <int> class Base, int D>
  std::unique_ptr<Base<D>> create(const Params& p) const {
    const PluginInfo* info = find(Base<D>::kind, p.type());
    if (!info) throw std::logic_error("no " + std::string(Base<D>::kind) + " named " + p.type());
    using Factory = std::function<std::unique_ptr<Base<D>>(const Params&)>;
    return std::any_cast<const Factory&>(info->factories[D - 1])(p);
  }

  /// The plugin used when a config omits a key of this kind (declared by the plugin itself with
  /// LOAM_REGISTER_DEFAULT), or "".
  std::string default_of(const std::string& kind) const;
  void set_default(const std::string& kind, const std::string& name) { defaults_[kind] = name; }
  /// The plugin a bare YAML list stands for in this kind (fields: a constant value), or "".
  std::string list_shorthand(const std::string& kind) const;
  void set_list_shorthand(const std::string& kind, const std::string& name) {
    shorthand_[kind] = name;
  }

  /// Label attached to plugins registered while loading a shared library.
  std::string loading_origin = "built-in";

 private:
  std::vector<KindInfo> kinds_;
  std::map<std::string, std::map<std::string, PluginInfo>> plugins_;
  std::map<std::string, std::string> defaults_, shorthand_;
};

template <template <int> class Base, template <int> class Impl>
bool register_plugin(bool as_default = false) {
  PluginInfo info;
  info.kind = Base<1>::kind;
  info.name = Impl<1>::name;
  info.summary = Impl<1>::summary;
  info.schema = &Impl<1>::schema;
  info.factories[0] = std::function<std::unique_ptr<Base<1>>(const Params&)>(
      [](const Params& p) { return std::make_unique<Impl<1>>(p); });
  info.factories[1] = std::function<std::unique_ptr<Base<2>>(const Params&)>(
      [](const Params& p) { return std::make_unique<Impl<2>>(p); });
  info.factories[2] = std::function<std::unique_ptr<Base<3>>(const Params&)>(
      [](const Params& p) { return std::make_unique<Impl<3>>(p); });
  if (as_default) Registry::instance().set_default(info.kind, info.name);
  Registry::instance().add(std::move(info));
  return true;
}

/// Load an out-of-tree plugin library; it must export
///   extern "C" int loam_plugin_abi_version();
/// and register its classes with LOAM_REGISTER at load time. Returns "" or an error message.
std::string load_plugin_library(const std::string& path);

}  // namespace loam

#define LOAM_CONCAT_INNER(a, b) a##b
#define LOAM_CONCAT(a, b) LOAM_CONCAT_INNER(a, b)
#define LOAM_REGISTER(BASE, IMPL)                                                                \
  namespace {                                                                                    \
  [[maybe_unused]] const bool LOAM_CONCAT(loam_registered_,                                      \
                                          IMPL) = ::loam::register_plugin<::loam::BASE, IMPL>(); \
  }
/// Register a plugin and make it the one used when a config omits its key.
#define LOAM_REGISTER_DEFAULT(BASE, IMPL)                           \
  namespace {                                                       \
  [[maybe_unused]] const bool LOAM_CONCAT(loam_registered_, IMPL) = \
      ::loam::register_plugin<::loam::BASE, IMPL>(true);            \
  }
#define LOAM_REGISTER_KIND_SHORTHAND(KIND, NAME)                           \
  namespace {                                                              \
  [[maybe_unused]] const bool LOAM_CONCAT(loam_shorthand_, __LINE__) =     \
      (::loam::Registry::instance().set_list_shorthand(KIND, NAME), true); \
  }
#define LOAM_REGISTER_KIND(KIND, DOC)                             \
  namespace {                                                     \
  [[maybe_unused]] const bool LOAM_CONCAT(loam_kind_, __LINE__) = \
      (::loam::Registry::instance().add_kind(KIND, DOC), true);   \
  }
