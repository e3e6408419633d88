#include "vdyn/core/scene_file.h"
#include "vdyn/core/animation.h"
#include "vdyn/core/plot.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "vdyn/core/file_io.h"
#include "vdyn/core/key_path.h"
#include "vdyn/core/plugin_library.h"

namespace vdyn {

// ---------------------------------------------------------------------------
// Table, Analysis
void Table::writeCsv(const std::string& path) const {
  std::ostringstream out;
  for (std::size_t i = 0; i < columns.size(); ++i) out << (i ? "," : "") << columns[i];
  out << '\n' << std::setprecision(17);
  for (const auto& row : rows) {
    for (std::size_t i = 0; i < row.size(); ++i) out << (i ? "," : "") << row[i];
    out << '\n';
  }
  writeFileAtomic(path, out.str());
}

AnalysisResult Analysis::run(const AnalysisContext& context) const {
  if (!context.built.vehicle) throw Error(type_ + " analysis: the scene has no vehicle");
  return DoRun(context);
}

// ---------------------------------------------------------------------------
// Overrides
Override Override::parse(const std::string& text, const std::string& option) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw Error(option + " '" + text + "': expected key.path=value");
  Override o;
  o.key_path = text.substr(0, eq);
  KeyPath::parse(o.key_path, option + " '" + text + "'");  // a malformed path is named here
  const std::string v = text.substr(eq + 1);
  // nan, inf and numbers beyond a double are named here: silently turned into
  // a string (or the JSON library's raw text) they would name nothing.
  std::string lower;
  for (char c : v) lower += char(std::tolower(static_cast<unsigned char>(c)));
  const std::string bare = (!lower.empty() && (lower[0] == '-' || lower[0] == '+')) ? lower.substr(1) : lower;
  if (bare == "nan" || bare == "inf" || bare == "infinity")
    throw Error(option + " '" + text + "': " + v + " is not a finite number");
  requireJsonDepth(v, option + " '" + o.key_path + "=...'");
  try {
    o.value = Json::parse(v);
  } catch (const Json::out_of_range&) {
    throw Error(option + " '" + text + "': number out of range (not a finite double): " + v);
  } catch (const Json::exception&) {
    o.value = v;  // a bare word: a string
  }
  return o;
}

void applyOverride(Json& scene, const Override& o, const std::string& where) {
  KeyPath::parse(o.key_path, where).set(scene, o.value, where);
}

// ---------------------------------------------------------------------------
// SceneDescription
namespace {
/// Removes the members a merge patch deletes (null values), recursively.
Json withoutNulls(const Json& patch) {
  if (!patch.is_object()) return patch;
  Json out = Json::object();
  for (auto it = patch.begin(); it != patch.end(); ++it)
    if (!it.value().is_null()) out[it.key()] = withoutNulls(it.value());
  return out;
}

/// JSON merge patch (RFC 7396) of `patch` over `base`, except that a typed
/// block is replaced, not merged, when the patch changes its kind: an object
/// whose "type" (a command, a plugin, an analysis) or "template" (a subsystem)
/// differs from the base's takes the patch's keys only. Merged, the base's
/// keys of the old kind would be unknown keys of the new one (a "hold"
/// command derived from a "smooth_step" would keep start_time_s).
void mergeTyped(Json& base, const Json& patch) {
  if (!patch.is_object()) {
    base = patch;
    return;
  }
  if (!base.is_object()) {
    base = withoutNulls(patch);
    return;
  }
  for (const char* kind : {"type", "template"}) {
    if (patch.contains(kind) && base.contains(kind) && patch[kind] != base[kind]) {
      base = withoutNulls(patch);
      return;
    }
  }
  for (auto it = patch.begin(); it != patch.end(); ++it) {
    if (it.value().is_null())
      base.erase(it.key());
    else
      mergeTyped(base[it.key()], it.value());
  }
}

/// The base's plugin list with a derived scene's "plugins" merged over it by
/// name: an entry whose "name" is a base plugin's is merged over that entry
/// (mergeTyped), "remove": true removes it, a new name is appended.
Json mergePluginsByName(Json base, const Json& derived, const std::string& where) {
  if (!base.is_array()) base = Json::array();
  if (!derived.is_array()) throw Error(where + ": expected an array of plugin entries, got " + derived.dump());
  for (std::size_t i = 0; i < derived.size(); ++i) {
    const Json& e = derived[i];
    const std::string w = where + "[" + std::to_string(i) + "]";
    if (!e.is_object() || !e.contains("name") || !e["name"].is_string())
      throw Error(w + ": a derived scene's plugin entry needs a \"name\" (it merges over the base's plugin of that "
                  "name, or is added; \"plugins_replace\": true replaces the base's list), got " + e.dump());
    const std::string name = e["name"].get<std::string>();
    auto it = std::find_if(base.begin(), base.end(),
                           [&](const Json& b) { return b.is_object() && b.value("name", std::string()) == name; });
    const bool remove = e.contains("remove");
    if (remove) {
      if (e["remove"] != Json(true)) throw Error(w + ".remove: expected true, got " + e["remove"].dump());
      if (e.size() != 2) throw Error(w + ": an entry with \"remove\": true has only \"name\" and \"remove\"");
      if (it == base.end())
        throw Error(w + ".remove: the base scene has no plugin '" + name + "' to remove");
      base.erase(it);
    } else if (it != base.end()) {
      mergeTyped(*it, e);
    } else {
      base.push_back(e);
    }
  }
  return base;
}

/// A scene file with "based_on": "<scene>" is that scene with its own keys
/// merged over it (mergeTyped: a JSON merge patch that replaces a block whose
/// "type" or "template" it changes), except "analysis", which replaces the
/// base's whole (a derived scene runs another analysis on the same scene), and
/// "plugins", merged by name (mergePluginsByName) unless "plugins_replace": true
/// says the list replaces the base's.
Json readSceneWithBase(const std::string& resolved, int depth) {
  Json j = readJsonFile(resolved);
  if (!j.is_object() || !j.contains("based_on")) return j;
  if (!j["based_on"].is_string()) throw Error(resolved + ": based_on: expected a scene file name, got " + j["based_on"].dump());
  if (depth >= 8) throw Error(resolved + ": based_on: chain deeper than 8 files (a cycle?)");
  Json base = readSceneWithBase(resolveDataPath(j["based_on"].get<std::string>(), resolved), depth + 1);
  j.erase("based_on");
  if (j.contains("analysis")) base.erase("analysis");
  bool replace = false;
  if (j.contains("plugins_replace")) {
    if (!j["plugins_replace"].is_boolean())
      throw Error(resolved + ": plugins_replace: expected true or false, got " + j["plugins_replace"].dump());
    replace = j["plugins_replace"].get<bool>();
    if (replace && !j.contains("plugins"))
      throw Error(resolved + ": plugins_replace: true needs a \"plugins\" list to replace the base's with");
    j.erase("plugins_replace");
  }
  if (j.contains("plugins") && !replace)
    j["plugins"] = mergePluginsByName(base.contains("plugins") ? base["plugins"] : Json::array(), j["plugins"],
                                      resolved + ": plugins");
  if (j.contains("plugins")) base.erase("plugins");  // merge_patch would merge nothing into an array anyway
  mergeTyped(base, j);
  return base;
}
}  // namespace

SceneDescription SceneDescription::fromFile(const std::string& path, const PluginRegistry& registry,
                                            const std::vector<Override>& overrides) {
  const std::string resolved = resolveDataPath(path);
  SceneDescription d = fromJson(readSceneWithBase(resolved, 0), resolved, registry);
  return overrides.empty() ? d : d.withOverrides(overrides);
}

SceneDescription SceneDescription::fromJson(Json scene, const std::string& sourcePath,
                                            const PluginRegistry& registry) {
  if (!scene.is_object()) throw Error((sourcePath.empty() ? "scene" : sourcePath) + ": expected a JSON object");
  SceneDescription d;
  d.json_ = std::make_shared<const Json>(std::move(scene));
  d.path_ = sourcePath;
  d.registry_ = &registry;
  return d;
}

std::string SceneDescription::name() const {
  if (json_->contains("name") && (*json_)["name"].is_string()) return (*json_)["name"].get<std::string>();
  std::string n = path_.substr(path_.find_last_of('/') + 1);
  if (n.size() > 5 && n.substr(n.size() - 5) == ".json") n.resize(n.size() - 5);
  return n.empty() ? "scene" : n;
}

SceneDescription SceneDescription::withOverrides(const std::vector<Override>& overrides) const {
  Json j = *json_;
  for (const auto& o : overrides) applyOverride(j, o, path_.empty() ? "scene" : path_);
  SceneDescription d = *this;
  d.json_ = std::make_shared<const Json>(std::move(j));
  return d;
}

std::string SceneDescription::resolve(const std::string& name) const {
  return resolveDataPath(name, path_.empty() ? "./scene" : path_);
}

std::vector<std::pair<std::string, std::string>> SceneDescription::pluginNamesAndTypes() const {
  std::vector<std::pair<std::string, std::string>> out;
  if (json_->contains("plugins") && (*json_)["plugins"].is_array())
    for (const Json& p : (*json_)["plugins"])
      if (p.is_object()) out.emplace_back(p.value("name", std::string()), p.value("type", std::string()));
  return out;
}

std::vector<std::string> SceneDescription::pluginLibraries() const {
  std::vector<std::string> libs;
  if (!json_->contains("plugin_libraries")) return libs;
  const Json& v = (*json_)["plugin_libraries"];
  const std::string where = (path_.empty() ? "scene" : path_) + ": plugin_libraries";
  if (!v.is_array()) throw Error(where + ": expected an array of file names, got " + v.dump());
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!v[i].is_string())
      throw Error(where + "[" + std::to_string(i) + "]: expected a file name, got " + v[i].dump());
    libs.push_back(resolve(v[i].get<std::string>()));
  }
  return libs;
}

namespace {
/// Prefixes a message with `where` unless it already names the file.
std::string located(const std::string& where, const std::string& fileTag, const std::string& msg) {
  if (msg.rfind(fileTag, 0) == 0) return msg;
  return where + ": " + msg;
}

/// Resolves the kind of a plugin entry: "kind" if given, else the one kind
/// (force element, constraint, controller) registering the type.
PluginKind pluginKind(const ParamReader& e, const std::string& type, const PluginRegistry& reg) {
  if (e.has("kind")) {
    const PluginKind k = kindFromKey(e.string("kind"), e.at("kind"));
    if (k == PluginKind::Vehicle || k == PluginKind::Analysis)
      throw Error(e.at("kind") + ": a plugin is a force_element, constraint or controller, not '" +
                  e.string("kind") + "'");
    return k;
  }
  std::vector<PluginKind> found;
  for (PluginKind k : {PluginKind::ForceElement, PluginKind::Constraint, PluginKind::Controller})
    if (reg.has(k, type)) found.push_back(k);
  if (found.size() == 1) return found[0];
  if (found.empty()) {
    std::string list;
    for (PluginKind k : {PluginKind::ForceElement, PluginKind::Constraint, PluginKind::Controller})
      for (const auto& n : reg.known(k)) list += (list.empty() ? "" : ", ") + n;
    throw Error(e.at("type") + ": unknown plugin '" + type + "'; known: " + (list.empty() ? "(none)" : list) +
                "; no force_element, constraint or controller library registers it: load the one that does with "
                "--plugin LIB.so or the scene's \"plugin_libraries\"");
  }
  throw Error(e.at("type") + ": '" + type + "' is registered for more than one kind; say \"kind\"");
}
}  // namespace

BuiltScene SceneDescription::load(std::vector<std::string>* errors) const {
  const std::string file = path_.empty() ? "scene" : path_;
  const ParamReader root = ParamReader::fromJson(*json_, file);
  const std::string fileTag = file + ":";
  // Runs one part; in check mode an error is recorded and the part's keys are
  // marked read (so they are not reported again as unknown).
  auto attempt = [&](const std::string& where, const ParamReader* part, const std::function<void()>& f) {
    try {
      f();
      return true;
    } catch (const Error& e) {
      if (!errors) throw Error(located(where, fileTag, e.what()));
      errors->push_back(located(where, fileTag, e.what()));
      if (part) part->markAllRead();
      return false;
    }
  };

  BuiltScene b;
  b.name = name();
  root.stringOr("name", "");
  root.stringOr("description", "");
  if (root.has("plugin_libraries")) attempt(root.at("plugin_libraries"), nullptr, [&] { pluginLibraries(); });

  // The vehicle.
  bool haveVehicle = false;
  {
    std::unique_ptr<ParamReader> v;
    attempt(root.at("vehicle"), nullptr, [&] { v = std::make_unique<ParamReader>(root.child("vehicle")); });
    if (v)
      haveVehicle = attempt(v->where(), v.get(), [&] {
        const std::string type = v->string("type");
        b.initial_speed_m_s = v->numberOr("initial_speed_m_s", 0.0);
        if (!(b.initial_speed_m_s >= 0 && b.initial_speed_m_s <= 100))
          throw Error(v->at("initial_speed_m_s") + " must lie in [0, 100] m/s, got " + formatValue(b.initial_speed_m_s));
        const std::string dataFile = resolveDataPath(v->string("data"), file);
        // The overrides merged over the data file: a key the vehicle's loader
        // never asks for is named by the scene's own key path
        // (vehicle.overrides...) when the user wrote it there, else by the data file's.
        ParamReader data = ParamReader::fromFile(dataFile);
        if (v->has("overrides")) data = data.mergedWith(v->child("overrides"));
        const VehicleSpec spec{type, data, registry_};
        b.vehicle = registry_->createVehicle(type, spec, v->at("type"));
        data.requireAllKeysRead();
      });
  }

  // Plugins, in order (a controller names the steering plugin added before it).
  bool pluginsOk = true;
  // Plugins not built, with their error's line in `errors`: their outputs are
  // not reported one by one (one root cause, one line).
  std::vector<std::string> failedPlugins;
  std::vector<std::size_t> failedLine;
  if (root.has("plugins")) {
    std::vector<ParamReader> entries;
    attempt(root.at("plugins"), nullptr, [&] { entries = root.array("plugins"); });
    for (const ParamReader& e : entries) {
      const bool ok = attempt(e.where(), &e, [&] {
        const std::string type = e.string("type");
        const std::string name = e.string("name");
        const PluginKind kind = pluginKind(e, type, *registry_);
        if (!registry_->has(kind, type)) registry_->create(kind, type, PluginSpec{name, e, {}, registry_}, e.at("type"));
        if (!haveVehicle) {
          e.markAllRead();  // the vehicle's error is reported; its plugins cannot be built
          return;
        }
        Attachment bindings;
        if (e.has("attach")) bindings = b.vehicle->getAttachment(e.string("attach"));
        if (e.has("bindings")) {
          const ParamReader bind = e.child("bindings");
          for (auto it = bind.json().begin(); it != bind.json().end(); ++it) bindings[it.key()] = bind.string(it.key());
        }
        b.scene().addPlugin(registry_->create(kind, type, PluginSpec{name, e, bindings, registry_}, e.at("type")));
      });
      pluginsOk &= ok;
      if (!ok && errors && e.json().is_object() && e.json().contains("name") && e.json()["name"].is_string()) {
        failedPlugins.push_back(e.json()["name"].get<std::string>());
        failedLine.push_back(errors->size() - 1);
      }
    }
  }

  // What can be known before a run: the vehicle's initial state against each
  // plugin (Plugin::checkInitialState: a speed hold at another speed than the
  // vehicle's). `vdyn check` makes that state here; a run meets the same check
  // in the transient analysis, before the solver. (An analysis that replaces
  // the scene's plugins, e.g. iso4138, runs regardless.)
  if (errors && haveVehicle && pluginsOk && root.has("plugins"))
    attempt(root.at("plugins"), nullptr, [&] {
      const SimTK::State initial = b.makeInitialState();
      for (const auto& p : b.scene().getPlugins()) p->checkInitialState(b.scene(), initial);
    });

  // Outputs to record.
  if (root.has("outputs")) {
    attempt(root.at("outputs"), nullptr, [&] {
      const Json& v = root.json().at("outputs");
      if (!v.is_array()) throw Error(root.at("outputs") + ": expected an array of output names, got " + v.dump());
      std::vector<std::size_t> dependent(failedPlugins.size(), 0);
      for (std::size_t i = 0; i < v.size(); ++i) {
        const std::string where = root.at("outputs") + "[" + std::to_string(i) + "]";
        if (!v[i].is_string()) throw Error(where + ": expected an output name, got " + v[i].dump());
        const std::string n = v[i].get<std::string>();
        const auto owner = std::find_if(failedPlugins.begin(), failedPlugins.end(), [&](const std::string& p) {
          return n.size() > p.size() && n.compare(0, p.size(), p) == 0 && n[p.size()] == '.';
        });
        if (haveVehicle && !b.scene().hasOutput(n) && owner != failedPlugins.end()) {
          ++dependent[std::size_t(owner - failedPlugins.begin())];  // one root cause, one line: summarised below
        } else if (haveVehicle && !b.scene().hasOutput(n)) {
          std::string list;
          for (const auto& k : b.scene().getOutputNames()) list += (list.empty() ? "" : ", ") + k;
          if (errors) errors->push_back(where + ": the scene has no output '" + n + "'; known: " + list);
          else throw Error(where + ": the scene has no output '" + n + "'; known: " + list);
        }
        b.outputs.push_back(n);
      }
      for (std::size_t k = 0; k < failedPlugins.size(); ++k)
        if (dependent[k])
          (*errors)[failedLine[k]] += " (and " + std::to_string(dependent[k]) + " output" +
                                      (dependent[k] == 1 ? "" : "s") + " of plugin '" + failedPlugins[k] +
                                      "' named in \"outputs\")";
    });
  }

  // The analysis (its factory reads and checks the settings).
  {
    std::unique_ptr<ParamReader> a;
    attempt(root.at("analysis"), nullptr, [&] { a = std::make_unique<ParamReader>(root.child("analysis")); });
    if (a)
      attempt(a->where(), a.get(), [&] {
        const std::string type = a->string("type");
        b.analysis = registry_->createAnalysis(type, *a, a->at("type"));
      });
  }

  // Every key of the file was asked for by someone.
  const auto unread = root.unreadKeys();
  if (errors) {
    errors->insert(errors->end(), unread.begin(), unread.end());
  } else if (!unread.empty()) {
    root.requireAllKeysRead();
  }
  return b;
}

BuiltScene SceneDescription::build() const { return load(nullptr); }

std::vector<std::string> SceneDescription::check() const {
  std::vector<std::string> errors;
  load(&errors);
  return errors;
}

void loadSceneLibraries(const SceneDescription& scene, PluginRegistry& registry) {
  for (const auto& lib : scene.pluginLibraries()) loadPluginLibrary(lib, registry);
}

std::vector<std::string> checkScene(const SceneDescription& scene, PluginRegistry& registry) {
  std::vector<std::string> errors;
  try {
    loadSceneLibraries(scene, registry);
  } catch (const Error& e) {
    errors.push_back(e.what());
  }
  for (const auto& e : scene.check()) errors.push_back(e);
  return errors;
}

std::string defaultOutputDir(const SceneDescription& scene) { return "results/" + scene.name(); }

Json runScene(const SceneDescription& scene, const RunOptions& options) {
  return runSceneWithTables(scene, options).summary;
}

SceneRun runSceneWithTables(const SceneDescription& scene, const RunOptions& options) {
  BuiltScene built = scene.build();
  if (!options.out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(options.out_dir, ec);
    if (ec) throw Error("cannot create output folder '" + options.out_dir + "': " + ec.message());
  }
  std::unique_ptr<AnimationRecorder> animation;
  if (options.animation) {
    if (options.out_dir.empty()) throw Error("--animation: no output folder to write animation.glb into");
    animation = std::make_unique<AnimationRecorder>(built.scene());
  }
  const AnalysisContext ctx{scene, built, options.out_dir, options.progress, animation.get()};
  AnalysisResult r = built.analysis->run(ctx);
  Json summary = {{"scene", scene.name()}, {"analysis", built.analysis->type()}};
  // What ran: the file and the scene's plugins as resolved (based_on merged,
  // --set applied), so that one inherited from a base scene is on record.
  if (!scene.path().empty()) summary["scene_file"] = scene.path();
  Json plugins = Json::array();
  for (const auto& [name, type] : scene.pluginNamesAndTypes()) plugins.push_back({{"name", name}, {"type", type}});
  summary["plugins"] = plugins;
  for (auto it = r.summary.begin(); it != r.summary.end(); ++it) summary[it.key()] = it.value();
  if (animation) {
    if (animation->size() < 2)
      throw Error("--animation: scene '" + scene.name() + "': analysis '" + built.analysis->type() +
                  "' sampled no time history of its scene (" + std::to_string(animation->size()) +
                  " samples; an animation needs a transient analysis with report_interval_s > 0, or iso3888_2)");
    Json files = Json::array();
    for (const auto& f : writeAnimation(*animation, options.out_dir + "/animation", scene.name()))
      files.push_back(std::filesystem::path(f).filename().string());
    summary["animation"] = files;
  }
  if (!options.out_dir.empty()) {
    for (const auto& [name, table] : r.tables) table.writeCsv(options.out_dir + "/" + name + ".csv");
    if (options.plots) {
      Json pngs = Json::array();
      for (const auto& f : renderPlots(options.out_dir, r.tables, r.plots))
        pngs.push_back(std::filesystem::path(f).filename().string());
      if (!pngs.empty()) summary["plots"] = pngs;
    }
    const std::string path = options.out_dir + "/summary.json";
    writeFileAtomic(path, summary.dump(2) + "\n");
  }
  SceneRun run{std::move(summary), std::move(r.tables), {{"t_s", "s"}}};
  for (const auto& n : built.scene().getOutputNames()) run.units[n] = built.scene().getOutput(n).unit;
  return run;
}

Json runSceneFile(const std::string& path, const std::vector<Override>& overrides, PluginRegistry& registry,
                  const RunOptions& options) {
  const SceneDescription scene = SceneDescription::fromFile(path, registry, overrides);
  loadSceneLibraries(scene, registry);
  return runScene(scene, options);
}

}  // namespace vdyn
