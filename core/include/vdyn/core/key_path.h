#pragma once
// KeyPath: the one way to name a value inside a JSON document (a scene, a
// sweep's summary, a vehicle data file): `--set`, derived scenes' overrides,
// sweep keys and collected summary paths, and sensitivity design parameters
// all parse and walk their paths here.
//
// Syntax: parts separated by '.', each a key; "[n]" after a part selects
// element n of an array ("a.b[2].c"). At an array a part of digits is an
// index too ("a.b.2.c"); any other part selects the element of an array of
// objects whose "name" is that text ("plugins.front_steer.command.final_rad").
// At an object, consecutive parts may also name one key that holds dots (an
// output name: "steady.chassis.yaw_rate_rad_s" is key "chassis.yaw_rate_rad_s"
// under "steady"); the longest key that exists wins.
//
// Every error has one form, naming the path, the part that failed and what
// was found there:
//   "<where>: key path 'a.steps[5]': a.steps has 2 elements, no [5]"
//   "<where>: key path 'a..b': empty part (expected e.g. a.b[2].c)"
#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace vdyn {

using Json = nlohmann::json;

class KeyPath {
 public:
  /// One part: a key (or an index or a "name" at an array), or an index
  /// written "[n]" (`bracketed`: only an array element, never a key).
  struct Part {
    std::string text;
    bool bracketed = false;
    bool operator==(const Part& o) const { return text == o.text && bracketed == o.bracketed; }
  };

  KeyPath() = default;
  /// Parses `text`; throws Error "<where>: key path '<text>': <why> (expected
  /// e.g. a.b[2].c)" if a part is empty, an index is not a number, or a
  /// character is not [A-Za-z0-9_-].
  static KeyPath parse(const std::string& text, const std::string& where);
  /// A path of plain keys (no parsing: a key may hold any character).
  static KeyPath ofKeys(const std::vector<std::string>& keys);

  /// The path as text, parsed back to the same parts ("a.b[2].c").
  std::string format() const;
  const std::vector<Part>& parts() const { return parts_; }
  bool empty() const { return parts_.empty(); }
  /// This path with `key` appended as a plain key.
  KeyPath child(const std::string& key) const;
  /// True if the first parts of this path are `prefix`'s.
  bool startsWith(const KeyPath& prefix) const;
  /// This path without its first `n` parts.
  KeyPath tail(std::size_t n) const;
  /// `prefix` followed by this path's parts.
  KeyPath under(const KeyPath& prefix) const;
  bool operator==(const KeyPath& o) const { return parts_ == o.parts_; }

  /// The value at this path in `j`, or nullptr if a part is not there.
  const Json* find(const Json& j) const;
  /// The value at this path in `j`; throws Error (the one format, naming
  /// `where`) if a part is not there.
  const Json& get(const Json& j, const std::string& where) const;
  /// Sets `value` at this path in `j`, creating missing object keys (a null
  /// becomes an object); an array element must exist. Throws Error (the one
  /// format, naming `where`) if a part cannot be walked.
  void set(Json& j, Json value, const std::string& where) const;

 private:
  explicit KeyPath(std::vector<Part> parts) : parts_(std::move(parts)) {}
  std::vector<Part> parts_;
};

}  // namespace vdyn
