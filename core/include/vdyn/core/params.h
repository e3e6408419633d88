#pragma once
// Reading parameter structs from JSON data files.
//
// Convention (see README): every key that carries a physical quantity ends in
// its SI unit, e.g. "mass_kg", "stiffness_N_per_m", "damping_N_s_per_m",
// "position_m" (a 3-vector). A ParamReader names the file and the key path in
// every error, e.g. "quarter_car.json: suspension.stiffness_N_per_m: missing key".
// Loaders read into the same plain structs the C++ builders fill; range checks
// live in each struct's validate(), so both paths are checked by one function.
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>
#include <SimTKcommon.h>

#include "vdyn/core/error.h"

namespace vdyn {

using Json = nlohmann::json;

/// Reads and parses a JSON file; throws Error naming the file on I/O or syntax errors.
Json readJsonFile(const std::string& path);

/// Resolves a data-file name: an existing path is used as is, otherwise it is
/// looked up along dataSearchPath().
std::string resolveDataPath(const std::string& name);
/// Resolves a file name written inside another file (`namingFile`): an absolute
/// path as is; a relative one first in the folder of `namingFile`, then along
/// dataSearchPath(). Throws Error naming `namingFile` and every folder tried.
std::string resolveDataPath(const std::string& name, const std::string& namingFile);
/// The data search path: the folders of the VDYN_DATA_PATH environment variable
/// (':'-separated, in order), then the project's data folder (VDYN_DATA_DIR).
std::vector<std::string> dataSearchPath();

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
  const Json& json() const { return *node_; }
  /// "file.json: a.b" style location of this node, for messages.
  const std::string& where() const { return where_; }
  /// Location of a key under this node.
  std::string at(const std::string& key) const;

  /// Strict keys (CONTRACTS.md item 1). Every accessor above (has, number,
  /// ...Or, child, array, ...) records the key it was asked for, in a record
  /// shared by the readers of one root. unreadKeys() lists the location of every
  /// key under this node (recursing into the objects read through child() and
  /// array()) that was never asked for, with the nearest asked-for key of the
  /// same object as a hint; keys starting with '_' are comments and exempt.
  std::vector<std::string> unreadKeys() const;
  /// Throws Error listing unreadKeys() (one per line), if any. Loaders call it when done.
  void requireAllKeysRead() const;
  /// Marks every key under this node as read (a loader that gave up on a part
  /// after reporting its error, so the part's keys are not reported again).
  void markAllRead() const;

 private:
  struct Record {
    std::set<std::pair<const Json*, std::string>> asked;
    std::set<const Json*> visited;  ///< nodes a reader was made for
  };
  void note(const std::string& key) const;
  void collectUnread(const Json& node, const std::string& where, std::vector<std::string>& out) const;
  const Json& require(const std::string& key) const;
  std::shared_ptr<const Json> root_;
  const Json* node_;
  std::string where_;
  std::shared_ptr<Record> record_ = std::make_shared<Record>();
};

}  // namespace vdyn
