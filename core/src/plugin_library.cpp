#include "vdyn/core/plugin_library.h"

#include <dlfcn.h>

#include <filesystem>
#include <mutex>
#include <set>
#include <utility>

namespace vdyn {

namespace {
std::mutex& libMutex() {
  static std::mutex m;
  return m;
}
std::vector<std::string>& loadedList() {
  static std::vector<std::string> v;
  return v;
}
std::set<std::pair<std::string, const PluginRegistry*>>& loadedInto() {
  static std::set<std::pair<std::string, const PluginRegistry*>> s;
  return s;
}
}  // namespace

void loadPluginLibrary(const std::string& path, PluginRegistry& registry) {
  std::lock_guard<std::mutex> lock(libMutex());
  std::error_code ec;
  const std::string canonical = std::filesystem::canonical(path, ec).string();
  if (ec && !path.empty() && path[0] == '/') throw Error("plugin library '" + path + "': not found");
  if (ec) {
    std::error_code cwdError;
    const std::string cwd = std::filesystem::current_path(cwdError).string();
    throw Error("plugin library '" + path + "': not found (looked for " +
                (cwdError ? "" : cwd + "/") + path +
                "; a scene's plugin_libraries resolve relative to the scene, then along the data path)");
  }
  if (loadedInto().count({canonical, &registry})) return;

  void* handle = dlopen(canonical.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    const char* why = dlerror();
    throw Error("plugin library '" + path + "': cannot be loaded: " + (why ? why : "unknown dlopen error"));
  }
  using AbiFn = int (*)();
  using RegisterFn = void (*)(PluginRegistry&);
  auto abi = reinterpret_cast<AbiFn>(dlsym(handle, "vdyn_plugin_abi_version"));
  if (!abi)
    throw Error("plugin library '" + path +
                "': has no vdyn_plugin_abi_version() entry point (is it a vdyn plugin library? see "
                "vdyn/core/plugin_library.h)");
  const int version = abi();
  if (version != VDYN_PLUGIN_ABI_VERSION)
    throw Error("plugin library '" + path + "': built for plugin ABI version " + std::to_string(version) +
                ", this vdyn has version " + std::to_string(VDYN_PLUGIN_ABI_VERSION) + "; rebuild it against this vdyn");
  auto reg = reinterpret_cast<RegisterFn>(dlsym(handle, "vdyn_register_plugins"));
  if (!reg)
    throw Error("plugin library '" + path +
                "': has no vdyn_register_plugins(vdyn::PluginRegistry&) entry point (see vdyn/core/plugin_library.h)");
  try {
    reg(registry);
  } catch (const std::exception& e) {
    throw Error("plugin library '" + path + "': vdyn_register_plugins failed: " + e.what());
  }
  loadedInto().insert({canonical, &registry});
  loadedList().push_back(canonical);
}

std::vector<std::string> loadedPluginLibraries() {
  std::lock_guard<std::mutex> lock(libMutex());
  return loadedList();
}

}  // namespace vdyn
