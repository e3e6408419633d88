// vdyn list [NAME]: every registered name by kind, with its keys, units,
// defaults and one-line meaning (the field tables the loaders read with). NAME
// is a kind, a choice family or a type name (every kind or family that has a
// type of that name is printed). `vdyn list outputs SCENE` and `vdyn list
// attachments SCENE` build the scene and print what its vehicle and plugins
// provide: every output with its unit and stage, every attachment with its
// bindings. `vdyn list --markdown` prints the same field tables as Markdown:
// docs/scene_reference.md is that output (ctest Docs.SceneReferenceIsCurrent
// fails when the file and the tables differ).
#include <algorithm>
#include <cstdio>

#include "command.h"
#include "vdyn/core/scene_file.h"

namespace vdyn::cli {

int listCommand(const std::vector<std::string>& args) {
  namespace po = study::po;
  po::options_description opts("Options");
  opts.add_options()("kind", po::value<std::string>(),
                     "only this kind (vehicle, force_element, constraint, controller, analysis), choice family "
                     "(steering_command, rear_steer_strategy, sensitivity_method, ...) or type name (fourws, gim, "
                     "antiroll_bar, ...); or outputs | attachments with a SCENE")(
      "scene", po::value<std::string>(), "with outputs | attachments: the scene file whose built scene is listed")(
      "markdown", "print the field tables as Markdown (docs/scene_reference.md is `vdyn list --markdown`)");
  addCommonOptions(opts);
  po::variables_map vm;
  if (!parseArgs(command("list"), args, opts, {"kind", "scene"}, vm)) return 0;
  PluginRegistry& registry = registryWithPlugins(vm);
  const std::string what = vm.count("kind") ? vm["kind"].as<std::string>() : "";
  const bool markdown = vm.count("markdown") > 0;
  if (markdown && (what == "outputs" || what == "attachments"))
    throw Error("vdyn list --markdown: prints the registered types' field tables, not a scene's " + what);
  if (what == "outputs" || what == "attachments") {
    if (!vm.count("scene")) throw Error("vdyn list " + what + " SCENE: no scene file given");
    const SceneDescription d = SceneDescription::fromFile(vm["scene"].as<std::string>(), registry);
    const BuiltScene built = d.build();
    const Scene& sc = built.scene();
    if (what == "outputs") {
      std::printf("outputs of scene '%s' (%s; * recorded by its \"outputs\"):\n", built.name.c_str(), d.path().c_str());
      std::size_t w = 4;
      for (const auto& n : sc.getOutputNames()) w = std::max(w, n.size());
      for (const auto& n : sc.getOutputNames()) {
        const Output& o = sc.getOutput(n);
        const bool rec = std::find(built.outputs.begin(), built.outputs.end(), n) != built.outputs.end();
        std::printf("  %c %-*s  %-8s %s\n", rec ? '*' : ' ', int(w), n.c_str(), o.unit.empty() ? "1" : o.unit.c_str(),
                    SimTK::Stage(o.stage).getName().c_str());
      }
    } else {
      std::printf("attachments of scene '%s' (%s): a plugin's \"attach\" names one; its bindings:\n",
                  built.name.c_str(), d.path().c_str());
      for (const auto& a : built.vehicle->getAttachmentNames()) {
        std::string b;
        for (const auto& [key, value] : built.vehicle->getAttachment(a)) b += (b.empty() ? "" : ", ") + key + " = " + value;
        std::printf("  %-16s %s\n", a.c_str(), b.c_str());
      }
    }
    return 0;
  }
  if (vm.count("scene"))
    throw Error("vdyn list: a second argument ('" + vm["scene"].as<std::string>() +
                "') is only for vdyn list outputs | attachments SCENE");
  // Markdown table cells hold the field table's own text: '|' escaped everywhere; in prose cells also '<' (an
  // HTML tag to a renderer, as in r<N>) and '*' (emphasis); code cells (keys, defaults) keep the rest as written.
  auto cell = [](const std::string& text, bool code) {
    std::string out;
    for (char c : text) {
      if (c == '|') out += "\\|";
      else if (!code && c == '<') out += "&lt;";
      else if (!code && c == '*') out += "\\*";
      else out += c;
    }
    return out;
  };
  auto printType = [&](const std::string& type, const TypeInfo& info) {
    if (markdown) {
      std::printf("### %s\n\n", type.c_str());
      if (!info.summary.empty()) std::printf("%s\n\n", info.summary.c_str());
      if (info.fields.empty()) {
        std::printf("No keys.\n\n");
        return;
      }
      std::printf("| key | unit | default | meaning |\n|---|---|---|---|\n");
      for (const auto& f : info.fields) {
        // "required" and the like are words, not values: only a JSON-looking default is code.
        const std::string& d = f.default_value;
        const bool word = d.empty() || d == "required" || d == "none" || (d.find(' ') != std::string::npos &&
                                                                       d.front() != '{' && d.front() != '[' &&
                                                                       d.front() != '"');
        const std::string def = word ? cell(d, false) : "`" + cell(d, true) + "`";
        std::printf("| `%s` | %s | %s | %s |\n", cell(f.key, true).c_str(),
                    f.unit.empty() ? "1" : cell(f.unit, false).c_str(), def.c_str(), cell(f.meaning, false).c_str());
      }
      std::printf("\n");
      return;
    }
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
  if (markdown)
    std::printf("# Scene reference\n\n"
                "Generated from the field tables the loaders read with: `build/bin/vdyn list --markdown > "
                "docs/scene_reference.md`.\nDo not edit it by hand; ctest `Docs.SceneReferenceIsCurrent` fails when "
                "it differs from the tables.\nEvery key of every registered kind and choice family, with its SI unit "
                "(`1` or `-`: none), default and meaning.\nA nested object's keys are listed as `params: key`, a vehicle's "
                "data-file keys as `data: key`.\nThe scene file format itself: [user guide, \"Scene files\"]"
                "(user_guide.md#scene-files).\n\n");
  for (PluginKind kind : kinds) {
    if (markdown)
      std::printf("## %s\n\n", toKey(kind));
    else
      std::printf("%s:\n", toKey(kind));
    for (const auto& type : registry.known(kind))
      if (onlyType.empty() || type == onlyType) printType(type, registry.info(kind, type));
    if (!markdown) std::printf("\n");
  }
  for (const auto& family : families) {
    if (markdown)
      std::printf("## %s\n\nA choice named inside a plugin or analysis.\n\n", family.c_str());
    else
      std::printf("%s (a choice named inside a plugin or analysis):\n", family.c_str());
    for (const auto& type : registry.knownChoices(family))
      if (onlyType.empty() || type == onlyType) printType(type, registry.choiceInfo(family, type));
    if (!markdown) std::printf("\n");
  }
  return 0;
}

}  // namespace vdyn::cli
