#pragma once
// Reading parameter structs from JSON data files.
//
// Convention (see docs/design_notes.md, "Conventions"): every key that carries a physical quantity ends in
// its SI unit, e.g. "mass_kg", "stiffness_N_per_m", "damping_N_s_per_m",
// "position_m" (a 3-vector). A ParamReader names the file and the key path in
// every error, e.g. "quarter_car.json: suspension.stiffness_N_per_m: missing key".
// Loaders read into the same plain structs the C++ builders fill; range checks
// live in each struct's validate(), so both paths are checked by one function.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <SimTKcommon.h>

#include "vdyn/core/error.h"

namespace vdyn {

using Json = nlohmann::json;

/// Reads and parses a JSON file (// comments allowed); throws Error naming the
/// file, and where it can the line, column and key path, on I/O or syntax
/// errors, an empty file, a number out of range (1e999) or a duplicate key.
Json readJsonFile(const std::string& path);
/// Parses JSON text; `name` names the source in messages (as readJsonFile).
Json parseJsonText(const std::string& text, const std::string& name);

/// Bounds on what the JSON readers accept (bounded input: a hostile or broken
/// file is a named Error, not a crash or an exhausted memory). No scene, data
/// or sweep file nests deeper than about 8 levels.
constexpr std::size_t kMaxJsonDepth = 100;                   ///< nested arrays/objects
constexpr std::size_t kMaxJsonFileBytes = 64u * 1024 * 1024;  ///< 64 MiB per file
/// Throws Error naming `name`, the depth reached, where it first passes
/// kMaxJsonDepth (line, column) and the limit, when `text` nests deeper
/// (brackets inside strings and comments are not counted).
void requireJsonDepth(const std::string& text, const std::string& name);

/// The folders a data-file name is looked up in when it is not an existing
/// path, in order: each folder of the environment variable VDYN_DATA_PATH
/// (':'-separated, read at every call), then the installed data folder
/// <prefix>/share/vdyn/data, found from the location of the vdyn_core library
/// (so an installed tree works wherever it is moved), or, when that folder
/// does not exist (a build tree), the source tree's vehicles/data.
std::vector<std::string> dataSearchPath();

/// Resolves a data-file name: an existing path is used as is, otherwise it is
/// looked up along dataSearchPath(); throws Error naming the file and every
/// folder looked in.
std::string resolveDataPath(const std::string& name);
/// Resolves a file name written inside another file (`namingFile`): an absolute
/// path as is; a relative one first in the folder of `namingFile`, then along
/// dataSearchPath(). Throws Error naming `namingFile` and every folder tried.
std::string resolveDataPath(const std::string& name, const std::string& namingFile);

/// Typed access to one object of a data file. Every accessor (has, number,
/// ...Or, child, array, raw) records the key it was asked for, present or not,
/// so requireAllKeysRead() can reject the keys nobody asked for: a misspelled
/// or unknown key is an error, never silently ignored. Copies and children
/// share the record. Keys starting with '_' are comments and never required.
class ParamReader {
 public:
  /// `where` names the source in messages (file name, optionally key path).
  ParamReader(std::shared_ptr<const Json> root, const Json* node, std::string where);
  static ParamReader fromFile(const std::string& path);
  static ParamReader fromJson(Json j, std::string where);

  bool has(const std::string& key) const;
  /// Required finite number.
  double number(const std::string& key) const;
  double numberOr(const std::string& key, double fallback) const;
  SimTK::Vec3 vec3(const std::string& key) const;
  SimTK::Vec3 vec3Or(const std::string& key, const SimTK::Vec3& fallback) const;
  std::vector<double> numbers(const std::string& key) const;
  std::string string(const std::string& key) const;
  std::string stringOr(const std::string& key, const std::string& fallback) const;
  bool boolean(const std::string& key) const;
  bool booleanOr(const std::string& key, bool fallback) const;
  int integer(const std::string& key) const;
  ParamReader child(const std::string& key) const;
  std::vector<ParamReader> array(const std::string& key) const;
  /// The raw value of a required key; the caller takes over checking it (the
  /// key and everything under it count as read).
  const Json& raw(const std::string& key) const;
  /// This node's raw JSON (read-only view; marks nothing as read).
  const Json& json() const { return *node_; }

  /// Throws Error naming the file and key path of every key under this node
  /// (nested objects and array elements opened through child()/array()
  /// included) that no accessor ever queried, each with the nearest queried key
  /// of its level as a hint ("did you mean ..."). Loaders call it when done.
  void requireAllKeysRead() const;
  /// The problems requireAllKeysRead() would report, one per unknown key
  /// ("file.json: a.b: unknown key (did you mean 'c'?)"); empty when all were read.
  std::vector<std::string> unreadKeys() const;
  /// Marks every key under this node as read (a loader that gave up on a part
  /// after reporting its error, so the part's keys are not reported again).
  void markAllRead() const;
  /// The keys any accessor asked this node for, present or not, sorted (the
  /// keys a loader reads; tests compare them with the field table's keys).
  std::vector<std::string> queriedKeys() const;
  /// This node with `patch` merged over it (RFC 7396 merge patch), as a new
  /// reader named like this one. Its requireAllKeysRead() checks the patch's
  /// keys first and names an unknown one by the patch's own key path (what the
  /// user wrote). This node and the patch count as read in their own readers.
  ParamReader mergedWith(const ParamReader& patch) const;
  /// "file.json: a.b" style location of this node, for messages.
  const std::string& where() const { return where_; }
  /// Location of a key under this node.
  std::string at(const std::string& key) const;

 private:
  struct Tracker;
  ParamReader(std::shared_ptr<const Json> root, const Json* node, std::string where,
              std::shared_ptr<Tracker> tracker);
  const Json& require(const std::string& key) const;
  void mark(const std::string& key) const;
  std::shared_ptr<const Json> root_;
  std::shared_ptr<Tracker> tracker_;
  const Json* node_;
  std::string where_;
};

}  // namespace vdyn
