// vdyn list [NAME]: every registered name by kind, with its keys, units,
// defaults and one-line meaning (the field tables the loaders read with). NAME
// is a kind, a choice family or a type name (every kind or family that has a
// type of that name is printed).
#include <algorithm>
#include <cstdio>

#include "command.h"

namespace vdyn::cli {

int listCommand(const std::vector<std::string>& args) {
  namespace po = study::po;
  po::options_description opts("Options");
  opts.add_options()("kind", po::value<std::string>(),
                     "only this kind (vehicle, force_element, constraint, controller, analysis), choice family "
                     "(steering_command, rear_steer_strategy, sensitivity_method, ...) or type name (fourws, gim, "
                     "antiroll_bar, ...)");
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
  std::string onlyType;  // a type name: only that type, in every kind and family that has it
  if (vm.count("kind")) {
    const std::string k = vm["kind"].as<std::string>();
    bool isKind = false;
    for (PluginKind kind : kinds) isKind = isKind || k == toKey(kind);
    if (std::find(families.begin(), families.end(), k) != families.end()) {
      kinds.clear();
      families = {k};
    } else if (isKind) {
      kinds = {kindFromKey(k, "vdyn list NAME")};
      families.clear();
    } else {
      std::vector<PluginKind> withType;
      std::vector<std::string> familiesWithType;
      for (PluginKind kind : kinds)
        if (registry.has(kind, k)) withType.push_back(kind);
      for (const auto& family : families)
        if (registry.hasChoice(family, k)) familiesWithType.push_back(family);
      if (withType.empty() && familiesWithType.empty()) {
        std::string known;
        for (PluginKind kind : kinds) known += std::string(known.empty() ? "" : ", ") + toKey(kind);
        for (const auto& family : families) known += ", " + family;
        throw Error("vdyn list NAME: '" + k + "' is no kind, choice family or registered type name; kinds and "
                    "families: " + known + " (vdyn list prints every type name)");
      }
      kinds = withType;
      families = familiesWithType;
      onlyType = k;
    }
  }
  for (PluginKind kind : kinds) {
    std::printf("%s:\n", toKey(kind));
    for (const auto& type : registry.known(kind))
      if (onlyType.empty() || type == onlyType) printType(type, registry.info(kind, type));
    std::printf("\n");
  }
  for (const auto& family : families) {
    std::printf("%s (a choice named inside a plugin or analysis):\n", family.c_str());
    for (const auto& type : registry.knownChoices(family))
      if (onlyType.empty() || type == onlyType) printType(type, registry.choiceInfo(family, type));
    std::printf("\n");
  }
  return 0;
}

}  // namespace vdyn::cli
