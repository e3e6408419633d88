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
};

/// What the registry knows about a registered type, for `vdyn list`.
struct TypeInfo {
  std::string summary;             ///< one line: what the type is
  std::vector<FieldInfo> fields;   ///< its keys
};

template <class T>
class FieldTable {
 public:
  /// A finite number; missing keys keep the member's current value unless required.
  FieldTable& number(const char* key, double T::*m, const char* unit, const char* meaning, bool required = false) {
    return add(key, unit, meaning, required,
               [=](const ParamReader& r, T& t) { if (required || r.has(key)) t.*m = r.number(key); },
               [=](const T& t, Json& j) { j[key] = t.*m; });
  }
  FieldTable& integer(const char* key, int T::*m, const char* unit, const char* meaning, bool required = false) {
    return add(key, unit, meaning, required,
               [=](const ParamReader& r, T& t) { if (required || r.has(key)) t.*m = r.integer(key); },
               [=](const T& t, Json& j) { j[key] = t.*m; });
  }
  FieldTable& boolean(const char* key, bool T::*m, const char* meaning) {
    return add(key, "-", meaning, false,
               [=](const ParamReader& r, T& t) { t.*m = r.booleanOr(key, t.*m); },
               [=](const T& t, Json& j) { j[key] = t.*m; });
  }
  FieldTable& string(const char* key, std::string T::*m, const char* meaning, bool required = false) {
    return add(key, "-", meaning, required,
               [=](const ParamReader& r, T& t) { if (required || r.has(key)) t.*m = r.string(key); },
               [=](const T& t, Json& j) { j[key] = t.*m; });
  }
  FieldTable& numbers(const char* key, std::vector<double> T::*m, const char* unit, const char* meaning,
                      bool required = false) {
    return add(key, unit, meaning, required,
               [=](const ParamReader& r, T& t) { if (required || r.has(key)) t.*m = r.numbers(key); },
               [=](const T& t, Json& j) { j[key] = t.*m; });
  }
  FieldTable& vec3(const char* key, SimTK::Vec3 T::*m, const char* unit, const char* meaning, bool required = false) {
    return add(key, unit, meaning, required,
               [=](const ParamReader& r, T& t) { if (required || r.has(key)) t.*m = r.vec3(key); },
               [=](const T& t, Json& j) { j[key] = {(t.*m)[0], (t.*m)[1], (t.*m)[2]}; });
  }
  FieldTable& strings(const char* key, std::vector<std::string> T::*m, const char* meaning) {
    return add(key, "-", meaning, false,
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
    entries_.push_back({{key, unit, defaultText, meaning}, false, std::move(read), std::move(write)});
    entries_.back().fixedDefault = true;
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
  std::vector<FieldInfo> describe() const {
    const T def{};
    std::vector<FieldInfo> out;
    for (const auto& e : entries_) {
      FieldInfo f = e.info;
      if (e.required) {
        f.default_value = "required";
      } else if (!e.fixedDefault) {
        Json j = Json::object();
        e.write(def, j);
        f.default_value = j.at(f.key).dump();
      }
      out.push_back(std::move(f));
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
  };
  FieldTable& add(const char* key, const char* unit, const char* meaning, bool required,
                  std::function<void(const ParamReader&, T&)> read, std::function<void(const T&, Json&)> write) {
    entries_.push_back({{key, unit, "", meaning}, required, std::move(read), std::move(write)});
    return *this;
  }
  std::vector<Entry> entries_;
};

}  // namespace vdyn
