#pragma once
// The one registry of every kind a scene file can name: vehicles (builders),
// force elements, constraints, controllers and analyses, each type with its
// factory and its TypeInfo (one-line summary and field table: keys, units,
// defaults, meanings) that `vdyn list` prints. Only what a scene lists is ever
// constructed, so a scene pays nothing for the others. An unknown name is an
// error that lists the known ones. Out-of-tree libraries add to it through
// vdyn_register_plugins (plugin_library.h).
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "vdyn/core/analysis.h"
#include "vdyn/core/fields.h"
#include "vdyn/core/params.h"
#include "vdyn/core/plugin.h"
#include "vdyn/core/vehicle.h"

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
  using VehicleFactory = std::function<std::unique_ptr<Vehicle>(const VehicleSpec&)>;
  /// Reads (and so validates) the analysis settings; throws Error naming the key.
  using AnalysisFactory = std::function<std::unique_ptr<Analysis>(const ParamReader& settings)>;

  /// Registers a plugin factory (force element, constraint, controller); throws
  /// if (kind, type) is already registered.
  void add(PluginKind kind, const std::string& type, Factory factory);
  void add(PluginKind kind, const std::string& type, Factory factory, TypeInfo info);
  /// Registers a vehicle builder (kind Vehicle).
  void addVehicle(const std::string& type, VehicleFactory factory, TypeInfo info);
  /// Registers an analysis (kind Analysis).
  void addAnalysis(const std::string& type, AnalysisFactory factory, TypeInfo info);

  bool has(PluginKind kind, const std::string& type) const;
  /// Sorted type names of one kind.
  std::vector<std::string> known(PluginKind kind) const;
  /// The documentation registered with a type (empty TypeInfo if none was given).
  const TypeInfo& info(PluginKind kind, const std::string& type) const;

  /// Creates a plugin; `where` names the data-file location in messages.
  std::unique_ptr<Plugin> create(PluginKind kind, const std::string& type,
                                 const PluginSpec& spec, const std::string& where) const;
  std::unique_ptr<Vehicle> createVehicle(const std::string& type, const VehicleSpec& spec,
                                         const std::string& where) const;
  std::unique_ptr<Analysis> createAnalysis(const std::string& type, const ParamReader& settings,
                                           const std::string& where) const;

 private:
  void requireNew(PluginKind kind, const std::string& type) const;
  [[noreturn]] void unknown(PluginKind kind, const std::string& type, const std::string& where) const;
  std::map<std::pair<PluginKind, std::string>, Factory> factories_;
  std::map<std::string, VehicleFactory> vehicles_;
  std::map<std::string, AnalysisFactory> analyses_;
  std::map<std::pair<PluginKind, std::string>, TypeInfo> infos_;
};

/// Every kind, in the order `vdyn list` prints them.
const std::vector<PluginKind>& allKinds();
/// The scene-file spelling of a kind: "vehicle", "force_element", "constraint",
/// "controller", "analysis".
const char* toKey(PluginKind kind);
/// Inverse of toKey; throws Error naming `where` and listing the spellings.
PluginKind kindFromKey(const std::string& key, const std::string& where);

}  // namespace vdyn
