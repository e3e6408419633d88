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
#include <typeinfo>
#include <vector>

#include "vdyn/core/analysis.h"
#include "vdyn/core/fields.h"
#include "vdyn/core/params.h"
#include "vdyn/core/plugin.h"
#include "vdyn/core/vehicle.h"

namespace vdyn {

class PluginRegistry;

/// What a factory receives: its parameters (the data-file object) and the
/// instance name the scene will know it by.
struct PluginSpec {
  std::string name;
  ParamReader params;
  /// Names a vehicle builder binds for the plugin (e.g. "wheel" -> "rf.wheel");
  /// a binding takes precedence over a string key of the same name in params.
  std::map<std::string, std::string> bindings = {};
  /// The registry the scene is built from: a factory looks up the choices it
  /// makes by name there (a steering command, a rear-steer strategy), so
  /// out-of-tree ones are found too. nullptr = the library's built-ins only.
  const PluginRegistry* registry = nullptr;
  std::string bound(const std::string& key) const {
    auto it = bindings.find(key);
    return it != bindings.end() ? it->second : params.string(key);
  }
};

/// Empty context of a choice family whose factories need only their parameters.
struct NoContext {};

/// A choice made by name inside a plugin or an analysis: a steering command
/// ("steering_command": hold, smooth_step, steps), a rear-steer strategy
/// ("rear_steer_strategy": 2ws, linear, nonlinear), a sensitivity method
/// ("sensitivity_method": fd_forward, fd_central, mixed, reference). Each
/// family has one interface Base and one Context its factories receive besides
/// their parameters (the data-file object that names the choice); the library
/// that defines a family registers its built-ins, an out-of-tree library adds
/// more with addChoice in vdyn_register_plugins, and `vdyn list` prints them.
template <class Base, class Context = NoContext>
using ChoiceFactory = std::function<std::unique_ptr<Base>(const ParamReader& params, const Context& context)>;

namespace detail {
/// T in a non-deduced context (std::type_identity of C++20): addChoice<Base>
/// takes a lambda and the Context default.
template <class T>
struct NonDeduced {
  using type = T;
};
}  // namespace detail

class PluginRegistry {
 public:
  using Factory = std::function<std::unique_ptr<Plugin>(const PluginSpec&)>;
  using VehicleFactory = std::function<std::unique_ptr<Vehicle>(const VehicleSpec&)>;
  /// Reads (and so validates) the analysis settings; throws Error naming the key.
  using AnalysisFactory = std::function<std::unique_ptr<Analysis>(const ParamReader& settings)>;


  // Every registration takes the type's TypeInfo, built with typeInfo(summary,
  // table) from the FieldTable its factory reads with (fields.h), so the keys
  // `vdyn list` prints are the keys the factory accepts.

  /// Registers a plugin factory (force element, constraint, controller); throws
  /// if (kind, type) is already registered.
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

  /// An analysis whose settings name choices (e.g. sensitivity methods): its
  /// factory also receives the registry, to create or check them at load time.
  using AnalysisFactoryWithRegistry =
      std::function<std::unique_ptr<Analysis>(const ParamReader& settings, const PluginRegistry& registry)>;
  void addAnalysis(const std::string& type, AnalysisFactoryWithRegistry factory, TypeInfo info);

  // --- choices inside plugins and analyses (see ChoiceFactory) ---------------
  /// Registers `type` in `family`; throws if it is already registered, or if
  /// the family was registered with another Base or Context.
  template <class Base, class Context = NoContext>
  void addChoice(const std::string& family, const std::string& type,
                 typename detail::NonDeduced<ChoiceFactory<Base, Context>>::type factory, TypeInfo info) {
    if (!factory) throw Error(family + " factory for '" + type + "' is empty");
    addChoiceErased(family, type, typeid(ChoiceFactory<Base, Context>).name(),
                    std::make_shared<ChoiceFactory<Base, Context>>(std::move(factory)), std::move(info));
  }
  /// Creates `type` of `family`. Throws Error "<where>: unknown <family> '<type>';
  /// known: ..." (family with blanks for underscores; no prefix if `where` is
  /// empty) if there is none.
  template <class Base, class Context = NoContext>
  std::unique_ptr<Base> createChoice(const std::string& family, const std::string& type, const ParamReader& params,
                                     const Context& context, const std::string& where) const {
    const auto* f = static_cast<const ChoiceFactory<Base, Context>*>(
        choiceFactory(family, type, typeid(ChoiceFactory<Base, Context>).name(), where));
    auto made = (*f)(params, context);
    if (!made) throw Error((where.empty() ? "" : where + ": ") + family + " '" + type + "' factory returned nothing");
    return made;
  }
  bool hasChoice(const std::string& family, const std::string& type) const;
  /// The families registered, sorted.
  std::vector<std::string> choiceFamilies() const;
  /// Sorted type names of one family (empty if the family is unknown).
  std::vector<std::string> knownChoices(const std::string& family) const;
  const TypeInfo& choiceInfo(const std::string& family, const std::string& type) const;

 private:
  void requireNew(PluginKind kind, const std::string& type) const;
  [[noreturn]] void unknown(PluginKind kind, const std::string& type, const std::string& where) const;
  std::map<std::pair<PluginKind, std::string>, Factory> factories_;
  std::map<std::string, VehicleFactory> vehicles_;
  std::map<std::string, AnalysisFactoryWithRegistry> analyses_;
  std::map<std::pair<PluginKind, std::string>, TypeInfo> infos_;
  struct Choice {
    std::string signature;                 ///< mangled ChoiceFactory<Base, Context> type
    std::shared_ptr<const void> factory;   ///< a ChoiceFactory<Base, Context>
    TypeInfo info;
  };
  void addChoiceErased(const std::string& family, const std::string& type, const std::string& signature,
                       std::shared_ptr<const void> factory, TypeInfo info);
  const void* choiceFactory(const std::string& family, const std::string& type, const std::string& signature,
                            const std::string& where) const;
  std::map<std::pair<std::string, std::string>, Choice> choices_;
  std::map<std::string, std::string> familySignatures_;
};

/// Every kind, in the order `vdyn list` prints them.
const std::vector<PluginKind>& allKinds();
/// The scene-file spelling of a kind: "vehicle", "force_element", "constraint",
/// "controller", "analysis".
const char* toKey(PluginKind kind);
/// Inverse of toKey; throws Error naming `where` and listing the spellings.
PluginKind kindFromKey(const std::string& key, const std::string& where);

}  // namespace vdyn
