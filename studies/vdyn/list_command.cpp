// vdyn list [KIND]: every registered name by kind, with its keys, units,
// defaults and one-line meaning (the field tables the loaders read with).
#include <algorithm>
#include <cstdio>

#include "command.h"

namespace vdyn::cli {

int listCommand(const std::vector<std::string>& args) {
  namespace po = study::po;
  po::options_description opts("Options");
  opts.add_options()("kind", po::value<std::string>(),
                     "only this kind (vehicle, force_element, constraint, controller, analysis) or choice family "
                     "(steering_command, rear_steer_strategy, sensitivity_method, ...)");
  addCommonOptions(opts);
  po::variables_map vm;
  if (!parseArgs(command("list"), args, opts, {"kind"}, vm)) return 0;
  const PluginRegistry& registry = registryWithPlugins(vm);
  auto printType = [](const std::string& type, const TypeInfo& info) {
    std::printf("  %s%s%s\n", type.c_str(), info.summary.empty() ? "" : " -- ", info.summary.c_str());
    int kw = 4, dw = 7;
    for (const auto& f : info.fields) {
      kw = std::max(kw, static_cast<int>(f.key.size()));
      dw = std::max(dw, static_cast<int>(std::min<std::size_t>(f.default_value.size(), 24)));
    }
    for (const auto& f : info.fields)
      std::printf("      %-*s  %-10s %-*s  %s\n", kw, f.key.c_str(), f.unit.empty() ? "1" : f.unit.c_str(), dw,
                  f.default_value.c_str(), f.meaning.c_str());
  };
  // Kinds, then the choice families (named inside a plugin or analysis entry).
  std::vector<PluginKind> kinds = allKinds();
  std::vector<std::string> families = registry.choiceFamilies();
  if (vm.count("kind")) {
    const std::string k = vm["kind"].as<std::string>();
    if (std::find(families.begin(), families.end(), k) != families.end()) {
      kinds.clear();
      families = {k};
    } else {
      kinds = {kindFromKey(k, "vdyn list KIND")};
      families.clear();
    }
  }
  for (PluginKind kind : kinds) {
    std::printf("%s:\n", toKey(kind));
    for (const auto& type : registry.known(kind)) printType(type, registry.info(kind, type));
    std::printf("\n");
  }
  for (const auto& family : families) {
    std::printf("%s (a choice named inside a plugin or analysis):\n", family.c_str());
    for (const auto& type : registry.knownChoices(family)) printType(type, registry.choiceInfo(family, type));
    std::printf("\n");
  }
  return 0;
}

}  // namespace vdyn::cli
