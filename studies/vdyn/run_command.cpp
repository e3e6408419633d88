// vdyn run SCENE: load, override, run the scene's analysis, write the results.
#include <cstdio>
#include <iostream>

#include "command.h"
#include "vdyn/core/interrupt.h"
#include "vdyn/core/scene_file.h"

namespace vdyn::cli {

int runCommand(const std::vector<std::string>& args) {
  namespace po = study::po;
  po::options_description opts("Options");
  opts.add_options()("scene", po::value<std::string>(), "scene file (path, or a name along the data path)")(
      "set", po::value<std::vector<std::string>>()->composing(),
      "override a scene value: key.path=value (repeatable; e.g. vehicle.initial_speed_m_s=12, "
      "plugins.front_steer.command.final_rad=0.05, analysis.t_end_s=5)")(
      "out", po::value<std::string>(), "output folder (default: ./results/<scene name>)")(
      "no-plots", "write no PNG plots (gnuplot) next to the CSV files")(
      "animation",
      "also write animation.glb (glTF 2.0: the bodies as boxes and cylinders, their poses at every report time, "
      "the reference path) and animation.html, a viewer that opens offline (time slider, play; #t=1.5 shows t = "
      "1.5 s); transient analyses only (docs/animation.md)");
  addCommonOptions(opts);
  po::variables_map vm;
  if (!parseArgs(command("run"), args, opts, {"scene"}, vm)) return 0;
  if (!vm.count("scene")) throw Error("bad command line: no scene file given (vdyn run SCENE)");
  PluginRegistry& registry = registryWithPlugins(vm);
  std::vector<Override> overrides;
  if (vm.count("set"))
    for (const auto& s : vm["set"].as<std::vector<std::string>>()) overrides.push_back(Override::parse(s, "--set"));
  const SceneDescription scene = SceneDescription::fromFile(vm["scene"].as<std::string>(), registry, overrides);
  loadSceneLibraries(scene, registry);
  RunOptions options;
  options.out_dir = vm.count("out") ? vm["out"].as<std::string>() : defaultOutputDir(scene);
  options.progress = [](const std::string& label, double tEnd) { return study::progress(label, tEnd); };
  options.plots = !vm.count("no-plots");
  options.animation = vm.count("animation") != 0;
  installInterruptHandlers();  // SIGINT/SIGTERM: a transient stops at its next step, nothing is written
  Json summary;
  try {
    summary = runScene(scene, options);
  } catch (const Interrupted& e) {
    throw Interrupted(e.signal(), std::string(e.what()) + "; nothing written to " + options.out_dir);
  }
  study::endProgress();
  std::printf("vdyn run: %s (%s): %s/summary.json\n", scene.name().c_str(),
              summary.value("analysis", std::string("?")).c_str(), options.out_dir.c_str());
  for (auto it = summary.begin(); it != summary.end(); ++it)
    if (it.value().is_number()) std::printf("  %-32s %.10g\n", it.key().c_str(), it.value().get<double>());
  // The scene's plugins as resolved (a derived scene's inherited ones included).
  std::string list;
  for (const auto& [name, type] : scene.pluginNamesAndTypes()) list += (list.empty() ? "" : ", ") + name + " (" + type + ")";
  if (!list.empty()) std::printf("  plugins: %s\n", list.c_str());
  // Regime events (a spin-out, a lift-off): a result of the run, never silent.
  if (summary.contains("events") && summary["events"].is_array())
    for (const Json& e : summary["events"]) std::printf("  event: %s\n", e.value("message", e.dump()).c_str());
  return 0;
}

}  // namespace vdyn::cli
