// vdyn list [KIND]: every registered name by kind, with its keys, units,
// defaults and one-line meaning (the field tables the loaders read with).
#include <cstdio>

#include "command.h"

namespace vdyn::cli {

int listCommand(const std::vector<std::string>& args) {
  namespace po = study::po;
  po::options_description opts("Options");
  opts.add_options()("kind", po::value<std::string>(),
                     "only this kind: vehicle, force_element, constraint, controller, analysis");
  addCommonOptions(opts);
  po::variables_map vm;
  if (!parseArgs(command("list"), args, opts, {"kind"}, vm)) return 0;
  const PluginRegistry& registry = registryWithPlugins(vm);
  std::vector<PluginKind> kinds = allKinds();
  if (vm.count("kind")) kinds = {kindFromKey(vm["kind"].as<std::string>(), "vdyn list KIND")};
  for (PluginKind kind : kinds) {
    std::printf("%s:\n", toKey(kind));
    for (const auto& type : registry.known(kind)) {
      const TypeInfo& info = registry.info(kind, type);
      std::printf("  %s%s%s\n", type.c_str(), info.summary.empty() ? "" : " -- ", info.summary.c_str());
      for (const auto& f : info.fields)
        std::printf("      %-34s %-10s %-14s %s\n", f.key.c_str(), f.unit.empty() ? "1" : f.unit.c_str(),
                    f.default_value.c_str(), f.meaning.c_str());
    }
    std::printf("\n");
  }
  return 0;
}

}  // namespace vdyn::cli
