#pragma once
// Registry from the plugin type names used in data files to factories. Only the
// plugins a scene lists are ever constructed, so a scene pays nothing for the
// others. An unknown name is an error that lists the known ones.
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "vdyn/core/params.h"
#include "vdyn/core/plugin.h"

namespace vdyn {

/// What a factory receives: its parameters (the data-file object) and the
/// instance name the scene will know it by.
struct PluginSpec {
  std::string name;
  ParamReader params;
  /// Names a vehicle builder binds for the plugin (e.g. "wheel" -> "rf.wheel");
  /// a binding takes precedence over a string key of the same name in params.
  std::map<std::string, std::string> bindings = {};
  std::string bound(const std::string& key) const {
    auto it = bindings.find(key);
    return it != bindings.end() ? it->second : params.string(key);
  }
};

class PluginRegistry {
 public:
  using Factory = std::function<std::unique_ptr<Plugin>(const PluginSpec&)>;

  /// Registers a factory; throws if (kind, type) is already registered.
  void add(PluginKind kind, const std::string& type, Factory factory);
  bool has(PluginKind kind, const std::string& type) const;
  /// Sorted type names of one kind.
  std::vector<std::string> known(PluginKind kind) const;
  /// Creates a plugin; `where` names the data-file location in messages.
  std::unique_ptr<Plugin> create(PluginKind kind, const std::string& type,
                                 const PluginSpec& spec, const std::string& where) const;

 private:
  std::map<std::pair<PluginKind, std::string>, Factory> factories_;
};

}  // namespace vdyn
