#pragma once
// Scene files: one JSON file (// comments allowed) that describes a whole scene
// -- the vehicle (a registered builder and its data file), plugins of every
// kind with their parameters and bindings, the outputs to record and the
// analysis with its settings -- loaded, validated and run through the registry
// (registry.h). The format is described, with a complete annotated example, in
// docs/user_guide.md, "Scene files":
//
//   {
//     "name": "ch3_transient",
//     "plugin_libraries": ["libaero.so"],                    // optional, out-of-tree plugins
//     "vehicle": {"type": "fourws", "data": "appendix_a.json",
//                 "overrides": {"chassis": {"mass_kg": 900}}, // merged over the data file
//                 "initial_speed_m_s": 10},
//     "plugins": [{"kind": "constraint", "type": "steering", "name": "front_steer",
//                  "attach": "front_axle",                   // the vehicle's bindings
//                  "command": {"type": "hold", "angle_rad": 0.05}}],
//     "outputs": ["chassis.yaw_rate_rad_s"],
//     "analysis": {"type": "transient", "t_end_s": 20}
//   }
//
// File names in a scene resolve relative to the scene file, then along the
// data search path (params.h: VDYN_DATA_PATH, then the data folder). Every key
// is checked: a key no loader or factory asked for is an error naming the file
// and key path (ParamReader::requireAllKeysRead), with the nearest known key.
//
// Threads: a SceneDescription is an immutable value; build() and runScene()
// make a fresh Simbody system on each call, so several threads may run
// separate scenes (or the same description) at once. Only loading plugin
// libraries changes the registry: do it before starting threads
// (loadSceneLibraries is serialized and loads each library once).
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "vdyn/core/analysis.h"
#include "vdyn/core/params.h"
#include "vdyn/core/registry.h"
#include "vdyn/core/vehicle.h"

namespace vdyn {

/// A scene built from a description: the vehicle (owning the Scene with every
/// plugin added), the analysis made from the settings, and the run parameters.
struct BuiltScene {
  std::string name;                     ///< the scene's name
  std::unique_ptr<Vehicle> vehicle;
  std::unique_ptr<Analysis> analysis;
  double initial_speed_m_s = 0;         ///< vehicle.initial_speed_m_s, m/s
  std::vector<std::string> outputs;     ///< "outputs": recorded by the transient analyses

  Scene& scene() { return vehicle->updScene(); }
  const Scene& scene() const { return vehicle->getScene(); }
  /// The concrete vehicle (e.g. WheeledVehicle) for code that needs its own
  /// C++ API; throws Error if the scene's vehicle is another (Vehicle::getConcrete).
  template <class V>
  V& vehicleAs() { return vehicle->getConcrete<V>(); }
  template <class V>
  const V& vehicleAs() const { return vehicle->getConcrete<V>(); }
  /// The vehicle's initial state at initial_speed_m_s.
  SimTK::State makeInitialState() const { return vehicle->makeInitialState(initial_speed_m_s); }
};

/// One `--set key.path=value` override: `key_path` is a KeyPath
/// (vdyn/core/key_path.h): parts split at '.', an array element named by its
/// index ("plugins.0", "steps[1]") or, for arrays of objects, by its "name"
/// ("plugins.front_steer.command.final_rad"). The value is JSON (number,
/// true/false, [..], {..}, "..."), or else taken as a string.
struct Override {
  std::string key_path;
  Json value;
  /// Parses "key.path=value"; throws Error naming `option` (e.g. "--set") and the text.
  static Override parse(const std::string& text, const std::string& option = "--set");
};

/// Sets the override's value at its KeyPath in `scene` (KeyPath::set: missing
/// object keys are created; the strict key check then rejects a misspelt one).
/// Throws KeyPath's Error, naming `where`, the path and the part that failed.
void applyOverride(Json& scene, const Override& o, const std::string& where);

class SceneDescription {
 public:
  /// Reads a scene file (path as given, else along the data search path) and
  /// applies the overrides in order. Does not build anything yet.
  static SceneDescription fromFile(const std::string& path, const PluginRegistry& registry,
                                   const std::vector<Override>& overrides = {});
  /// A description from JSON; `sourcePath` is where relative file names
  /// resolve from and what messages name ("" = the working directory).
  static SceneDescription fromJson(Json scene, const std::string& sourcePath, const PluginRegistry& registry);

  const Json& json() const { return *json_; }
  /// The file it was read from (as resolved), or the sourcePath given.
  const std::string& path() const { return path_; }
  /// "name", or the file name without folder and ".json".
  std::string name() const;
  const PluginRegistry& registry() const { return *registry_; }
  /// The same description with overrides applied (analyses that rebuild the
  /// scene at other parameter values use this).
  SceneDescription withOverrides(const std::vector<Override>& overrides) const;
  SceneDescription withOverride(const std::string& keyPath, const Json& value) const {
    return withOverrides({Override{keyPath, value}});
  }
  /// A file named inside this scene, resolved (scene folder, then search path).
  std::string resolve(const std::string& name) const;
  /// "plugin_libraries", resolved.
  std::vector<std::string> pluginLibraries() const;
  /// The scene's plugins as resolved (based_on merged, overrides applied), in
  /// order: each entry's "name" and "type" ("" where absent; `vdyn check`
  /// reports those entries).
  std::vector<std::pair<std::string, std::string>> pluginNamesAndTypes() const;

  /// Builds the vehicle, adds every plugin, checks the outputs, makes the
  /// analysis and checks that every key was read. A fresh Simbody system each
  /// call. Throws the first Error.
  BuiltScene build() const;
  /// Validates the whole scene the way build() does but goes on after an
  /// error: returns every error found (one line each), empty when valid.
  std::vector<std::string> check() const;

 private:
  SceneDescription() = default;
  BuiltScene load(std::vector<std::string>* errors) const;
  std::shared_ptr<const Json> json_;
  std::string path_;
  const PluginRegistry* registry_ = nullptr;
};

/// Loads the description's plugin libraries into `registry` (plugin_library.h).
void loadSceneLibraries(const SceneDescription& scene, PluginRegistry& registry);

/// What `vdyn check` reports: the description's plugin libraries loaded into
/// `registry` (an error loading one is the first line), then every error of
/// SceneDescription::check(); empty when the scene is valid.
std::vector<std::string> checkScene(const SceneDescription& scene, PluginRegistry& registry);

struct RunOptions {
  /// Where summary.json, the tables and the analysis's files go; created if
  /// needed. "" writes no files (the summary is still returned).
  std::string out_dir;
  /// Progress of long runs (empty = none).
  ProgressFactory progress;
  /// PNG plots of the tables (plot.h, gnuplot) next to the CSV files.
  bool plots = true;
  /// An animation of the run (vdyn/core/animation.h): animation.glb and its
  /// viewer animation.html in out_dir, the bodies' poses X_GB sampled at the
  /// analysis's report times. Only an analysis that runs the built scene
  /// through a Recorder (transient) has one; others are an Error. Off: nothing
  /// extra is recorded.
  bool animation = false;
};

/// What a run of a scene gives: the summary (as in summary.json), the
/// analysis's tables (written as <name>.csv when there is an output folder)
/// and the unit of every output of the built scene ("" = dimensionless; the
/// tables' time column "t_s" is "s").
struct SceneRun {
  Json summary;
  std::vector<std::pair<std::string, Table>> tables;
  std::map<std::string, std::string> units;
};

/// Builds the scene, runs its analysis, writes the output files (none when
/// options.out_dir is "") and returns the summary and tables. `vdyn run`,
/// `vdyn sweep` and the Python module run scenes through this one function.
SceneRun runSceneWithTables(const SceneDescription& scene, const RunOptions& options = {});

/// runSceneWithTables(...).summary: the summary JSON ({"scene", "analysis",
/// ...the analysis's summary}).
Json runScene(const SceneDescription& scene, const RunOptions& options = {});

/// Loads a scene file, applies `overrides`, loads its plugin libraries into
/// `registry`, runs it (runScene) and returns the summary JSON. Safe to call
/// from several threads on separate scenes once the libraries are loaded.
Json runSceneFile(const std::string& path, const std::vector<Override>& overrides, PluginRegistry& registry,
                  const RunOptions& options = {});

/// The default output folder of a scene: ./results/<scene name> under the
/// working directory (never the source tree).
std::string defaultOutputDir(const SceneDescription& scene);

}  // namespace vdyn
