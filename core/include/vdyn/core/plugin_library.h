#pragma once
// Out-of-tree plugin libraries (CONTRACTS.md item 3). A shared library built
// against the installed vdyn package exports two C functions:
//
//   extern "C" int vdyn_plugin_abi_version() { return VDYN_PLUGIN_ABI_VERSION; }
//   extern "C" void vdyn_register_plugins(vdyn::PluginRegistry& registry) {
//     registry.add(vdyn::PluginKind::ForceElement, "aero_drag", makeAeroDrag,
//                  vdyn::typeInfo("summary", aeroDragFields()));
//   }
//
// (VDYN_PLUGIN_EXPORT below writes both declarations.) A scene names the
// library in "plugin_libraries", or `vdyn run --plugin PATH` loads it; then the
// scene names its types like built-in ones. Loading is plain dlopen/dlsym: the
// library shares the program's C++ runtime and vdyn libraries, which is what a
// plugin needs (it derives from vdyn classes), and the version check below
// refuses a library compiled against different vdyn headers.
#include <string>
#include <vector>

#include "vdyn/core/registry.h"

/// Bumped whenever a class a plugin derives from or calls (Plugin and its kinds,
/// PluginRegistry, PluginSpec, ParamReader, Scene, Vehicle, Analysis, TypeInfo)
/// changes its layout or virtual functions. 2: PluginSpec::registry, choices
/// in PluginRegistry, Vehicle::getConcrete/derivedData. 3: FieldInfo::type; every
/// registration takes its TypeInfo (typeInfo(summary, table)). 4: the vehicles'
/// subsystem templates (Suspension, AntiRollBar) as choice families a library
/// may add to; WheeledVehicle for FourWsVehicle. 5: Suspension::usesRack/setRack
/// (the rack and pinion), SteeringPlugin's rack members, Plugin::calcInputJumpTimes
/// and SteeringCommand::getRateJumpTimes. 6: Plugin::addDecorations (animations),
/// Scene's sample observer. 7: the sample observer moved from Scene to
/// Recorder's constructor (AnalysisContext::animation), SceneDecorations'
/// cone size. 9: the require* checks (vdyn/core/error.h) inline, taking the
/// name as a std::string_view; ReducedDenseRows::Arm names the knuckle's
/// ReducedKnuckleMobilizer (was its WishboneLoop). A library must return the value it was compiled with from
/// vdyn_plugin_abi_version().
#define VDYN_PLUGIN_ABI_VERSION 9

/// Declares the two entry points with C linkage and default visibility.
#define VDYN_PLUGIN_EXPORT extern "C" __attribute__((visibility("default")))

namespace vdyn {

/// Loads a plugin library (dlopen, RTLD_NOW | RTLD_LOCAL) and calls its
/// vdyn_register_plugins(registry). Throws Error naming the path if it cannot
/// be opened, lacks vdyn_plugin_abi_version or vdyn_register_plugins, or was
/// built for another VDYN_PLUGIN_ABI_VERSION (both numbers in the message).
/// A library is loaded once per process and registry (a second call with the
/// same file is a no-op); calls are serialized. The library stays loaded until
/// the process ends (its factories live in the registry).
void loadPluginLibrary(const std::string& path, PluginRegistry& registry);

/// The libraries loaded so far (canonical paths), in order.
std::vector<std::string> loadedPluginLibraries();

}  // namespace vdyn
