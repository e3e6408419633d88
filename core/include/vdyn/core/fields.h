#pragma once
// Field tables: one list of a parameter struct's keys that reads it from a data
// file, writes it back and documents it (`vdyn list`). The key, its SI unit,
// its default (from a default-constructed struct) and a one-line meaning are
// stated once, next to the member they fill, so the documentation cannot drift
// from what the loader accepts.
//
//   struct DragParams { double area_m2 = 2; double cd = 0.3; };
//   const FieldTable<DragParams>& dragFields() {
//     static const auto t = FieldTable<DragParams>()
//         .number("area_m2", &DragParams::area_m2, "m^2", "frontal area")
//         .number("cd", &DragParams::cd, "", "drag coefficient");
//     return t;
//   }
//   DragParams p = dragFields().read(reader);   // unknown keys: reader.requireAllKeysRead()
//
// A registered type is documented from its table: registry.add(kind, "drag",
// factory, typeInfo("summary", dragFields())). A nested object of the data
// file has its own table (object()); its keys are listed as "<object>: <key>".
// A struct that contains another (shared) struct as a member reads the
// member's keys at its own level (include()).
#include <functional>
#include <string>
#include <vector>

#include "vdyn/core/params.h"

namespace vdyn {

/// One documented key: what `vdyn list` prints for it.
struct FieldInfo {
  std::string key;            ///< data-file key (a quantity's key ends in its unit)
  std::string unit;           ///< SI unit; "" when dimensionless; "-" for names, flags, objects
  std::string default_value;  ///< JSON text of the default, or "required"
  std::string meaning;        ///< one line
  /// Value form: number, integer, boolean, string, numbers, vec3, strings,
  /// object, custom ("" for a hand-written entry).
  std::string type = "";
  /// JSON text of a valid value when the default is no JSON value (a custom
  /// key), for tests and examples; "" otherwise.
  std::string sample = "";
};

/// What the registry knows about a registered type, for `vdyn list`. Build it
/// with typeInfo(summary, table) from the field table the factory reads with.
struct TypeInfo {
  std::string summary;             ///< one line: what the type is
  std::vector<FieldInfo> fields;   ///< its keys
};

template <class T>
class FieldTable {
 public:
  /// A finite number; missing keys keep the member's current value unless required.
  FieldTable& number(const char* key, double T::*m, const char* unit, const char* meaning, bool required = false) {
    return add(key, unit, meaning, required, "number",
               [=](const ParamReader& r, T& t) { if (required || r.has(key)) t.*m = r.number(key); },
               [=](const T& t, Json& j) { j[key] = t.*m; });
  }
  FieldTable& integer(const char* key, int T::*m, const char* unit, const char* meaning, bool required = false) {
    return add(key, unit, meaning, required, "integer",
               [=](const ParamReader& r, T& t) { if (required || r.has(key)) t.*m = r.integer(key); },
               [=](const T& t, Json& j) { j[key] = t.*m; });
  }
  FieldTable& boolean(const char* key, bool T::*m, const char* meaning) {
    return add(key, "-", meaning, false, "boolean",
               [=](const ParamReader& r, T& t) { t.*m = r.booleanOr(key, t.*m); },
               [=](const T& t, Json& j) { j[key] = t.*m; });
  }
  FieldTable& string(const char* key, std::string T::*m, const char* meaning, bool required = false) {
    return add(key, "-", meaning, required, "string",
               [=](const ParamReader& r, T& t) { if (required || r.has(key)) t.*m = r.string(key); },
               [=](const T& t, Json& j) { j[key] = t.*m; });
  }
  FieldTable& numbers(const char* key, std::vector<double> T::*m, const char* unit, const char* meaning,
                      bool required = false) {
    return add(key, unit, meaning, required, "numbers",
               [=](const ParamReader& r, T& t) { if (required || r.has(key)) t.*m = r.numbers(key); },
               [=](const T& t, Json& j) { j[key] = t.*m; });
  }
  FieldTable& vec3(const char* key, SimTK::Vec3 T::*m, const char* unit, const char* meaning, bool required = false) {
    return add(key, unit, meaning, required, "vec3",
               [=](const ParamReader& r, T& t) { if (required || r.has(key)) t.*m = r.vec3(key); },
               [=](const T& t, Json& j) { j[key] = {(t.*m)[0], (t.*m)[1], (t.*m)[2]}; });
  }
  FieldTable& strings(const char* key, std::vector<std::string> T::*m, const char* meaning) {
    return add(key, "-", meaning, false, "strings",
               [=](const ParamReader& r, T& t) {
                 if (!r.has(key)) return;
                 const Json& v = r.json().at(key);
                 if (!v.is_array()) throw Error(r.at(key) + ": expected an array of strings, got " + v.dump());
                 (t.*m).clear();
                 for (const auto& e : v) {
                   if (!e.is_string()) throw Error(r.at(key) + ": expected an array of strings, got " + v.dump());
                   (t.*m).push_back(e.get<std::string>());
                 }
               },
               [=](const T& t, Json& j) { j[key] = t.*m; });
  }
  /// A key the struct's loader reads by hand (a nested object, a choice of
  /// forms): documented here, read by `read`.
  FieldTable& custom(const char* key, const char* unit, const char* defaultText, const char* meaning,
                     std::function<void(const ParamReader&, T&)> read,
                     std::function<void(const T&, Json&)> write = {}) {
    entries_.push_back({{key, unit, defaultText, meaning, "custom"}, false, std::move(read), std::move(write)});
    entries_.back().fixedDefault = true;
    return *this;
  }
  /// A valid value (JSON text) of the last key added, when its default is not
  /// one ("required", a custom key's description of its default).
  FieldTable& sample(const char* json) {
    entries_.back().info.sample = json;
    return *this;
  }
  /// A nested object read with its own table: r.child(key) when present (or
  /// always when required), its keys checked with the rest. Listed as the
  /// object's line and then each of its keys as "<key>: <sub key>".
  template <class S>
  FieldTable& object(const char* key, S T::*m, const FieldTable<S>& sub, const char* meaning, bool required = false) {
    add(key, "-", meaning, required, "object",
        [=](const ParamReader& r, T& t) { if (required || r.has(key)) sub.read(r.child(key), t.*m); },
        [=](const T& t, Json& j) { j[key] = sub.write(t.*m); });
    if (!required) entries_.back().fixedDefault = true, entries_.back().info.default_value = "{}";
    entries_.back().describeSub = [=](const T& def) {
      std::vector<FieldInfo> out = sub.describe(def.*m);
      for (auto& f : out) f.key = std::string(key) + ": " + f.key;
      return out;
    };
    return *this;
  }
  /// The keys of a member struct (a part several structs share) at this level.
  template <class S>
  FieldTable& include(S T::*m, const FieldTable<S>& sub) {
    Entry e;
    e.read = [=](const ParamReader& r, T& t) { sub.read(r, t.*m); };
    e.write = [=](const T& t, Json& j) { j.update(sub.write(t.*m)); };
    e.describeSub = [=](const T& def) { return sub.describe(def.*m); };
    e.inlined = true;
    entries_.push_back(std::move(e));
    return *this;
  }

  /// Reads every key of the table from `r` into `t` (missing optional keys keep `t`'s values).
  void read(const ParamReader& r, T& t) const {
    for (const auto& e : entries_) e.read(r, t);
  }
  T read(const ParamReader& r) const {
    T t{};
    read(r, t);
    return t;
  }
  /// The table's keys with `t`'s values (custom keys without a writer are left out).
  Json write(const T& t) const {
    Json j = Json::object();
    for (const auto& e : entries_)
      if (e.write) e.write(t, j);
    return j;
  }
  /// Keys, units, defaults (of a default-constructed T) and meanings.
  std::vector<FieldInfo> describe() const { return describe(T{}); }
  /// The same with the defaults of `def`.
  std::vector<FieldInfo> describe(const T& def) const {
    std::vector<FieldInfo> out;
    for (const auto& e : entries_) {
      if (e.inlined) {
        for (auto& f : e.describeSub(def)) out.push_back(std::move(f));
        continue;
      }
      FieldInfo f = e.info;
      if (e.required) {
        f.default_value = "required";
      } else if (!e.fixedDefault) {
        Json j = Json::object();
        e.write(def, j);
        f.default_value = j.at(f.key).dump();
      }
      out.push_back(std::move(f));
      if (e.describeSub)
        for (auto& g : e.describeSub(def)) out.push_back(std::move(g));
    }
    return out;
  }

 private:
  struct Entry {
    FieldInfo info;
    bool required = false;
    std::function<void(const ParamReader&, T&)> read;
    std::function<void(const T&, Json&)> write;
    bool fixedDefault = false;
    std::function<std::vector<FieldInfo>(const T&)> describeSub = {};  ///< object() or include() keys
    bool inlined = false;                                              ///< include(): no line of its own
  };
  FieldTable& add(const char* key, const char* unit, const char* meaning, bool required, const char* type,
                  std::function<void(const ParamReader&, T&)> read, std::function<void(const T&, Json&)> write) {
    entries_.push_back({{key, unit, "", meaning, type}, required, std::move(read), std::move(write)});
    return *this;
  }
  std::vector<Entry> entries_;
};

/// The table of a type that reads no keys of its own.
struct NoKeys {};
inline const FieldTable<NoKeys>& noFields() {
  static const FieldTable<NoKeys> t;
  return t;
}

/// The documentation of a registered type: its summary and the keys of the
/// table its factory reads with.
template <class T>
TypeInfo typeInfo(std::string summary, const FieldTable<T>& table) {
  return TypeInfo{std::move(summary), table.describe()};
}

}  // namespace vdyn
