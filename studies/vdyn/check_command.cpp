// vdyn check SCENE: validate a scene file (vehicle, plugins, bindings, outputs,
// analysis settings, unknown keys) without running it; every error at once.
#include <cstdio>

#include "command.h"
#include "vdyn/core/scene_file.h"

namespace vdyn::cli {

int checkCommand(const std::vector<std::string>& args) {
  namespace po = study::po;
  po::options_description opts("Options");
  opts.add_options()("scene", po::value<std::string>(), "scene file")(
      "set", po::value<std::vector<std::string>>()->composing(), "override a scene value: key.path=value")(
      "resolved", "print the resolved scene (based_on merged, --set applied) and its plugin list, then check it");
  addCommonOptions(opts);
  po::variables_map vm;
  if (!parseArgs(command("check"), args, opts, {"scene"}, vm)) return 0;
  if (!vm.count("scene")) throw Error("bad command line: no scene file given (vdyn check SCENE)");
  PluginRegistry& registry = registryWithPlugins(vm);
  std::vector<Override> overrides;
  if (vm.count("set"))
    for (const auto& s : vm["set"].as<std::vector<std::string>>()) overrides.push_back(Override::parse(s, "--set"));
  const SceneDescription scene = SceneDescription::fromFile(vm["scene"].as<std::string>(), registry, overrides);
  if (vm.count("resolved")) {
    const Json& j = scene.json();
    std::printf("%s\n", j.dump(2).c_str());
    std::printf("vdyn check: %s: plugins:", scene.path().c_str());
    for (const auto& [name, type] : scene.pluginNamesAndTypes())
      std::printf(" %s (%s)", name.empty() ? "?" : name.c_str(), type.empty() ? "?" : type.c_str());
    std::printf("\n");
  }
  const std::vector<std::string> errors = checkScene(scene, registry);
  for (const auto& e : errors) std::fprintf(stderr, "vdyn check: error: %s\n", e.c_str());
  if (!errors.empty()) return 1;
  std::printf("vdyn check: %s: ok\n", scene.path().c_str());
  return 0;
}

}  // namespace vdyn::cli
