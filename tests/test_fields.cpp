// Every registered type of standardRegistry(): the keys its factory accepts and
// reads are the keys `vdyn list` prints (its TypeInfo, built from the field
// table the factory reads with), and the other way round.
//
// For each type a params object is built from the listed keys alone: each key
// gets its default (or its sample, or a value of its form when it is
// required). Then
//   - the factory accepts it: it constructs, and requireAllKeysRead() finds no
//     unknown key (every listed key is accepted);
//   - every key the factory asked for (ParamReader::queriedKeys) is listed, and
//     every listed key was asked for (nothing listed that nobody reads);
//   - one extra key is rejected as an unknown key.
// Nested objects: a table's object() lists the object's keys as
// "<object>: <key>"; they are checked the same way one level down (the
// object's queried keys against its listed keys). Keys of a nested object that
// a custom entry hands to another struct's loader (a vehicle's chassis and
// corners, a tire block inside vehicle data) are checked there by that
// loader's requireAllKeysRead(): the vehicles are built from their real data
// files, so those loaders run here too. Vehicles list their scene keys (read
// by the scene loader) and their data keys as "data: <key>"; the data keys are
// checked against the data object.
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "test_util.h"
#include "vdyn/core/fields.h"
#include "vdyn/rear_steer/rear_steer.h"
#include "vdyn/sensitivity/sensitivity.h"
#include "vdyn/steering/steering.h"
#include "vdyn/steering_ratio/linear_ratio.h"
#include "vdyn/tire/tire_model.h"
#include "vdyn/templates/rack_and_pinion.h"
#include "vdyn/vehicles/standard_registry.h"
#include "vdyn/vehicles/anti_roll_bar.h"
#include "vdyn/vehicles/suspension.h"

using namespace vdyn;
using vdyn::test::errorOf;

namespace {

/// A value of the key's form: its sample, its default, or a plain value.
Json sampleOf(const FieldInfo& f, const std::string& what) {
  if (!f.sample.empty()) return Json::parse(f.sample);
  if (f.default_value != "required") {
    try {
      return Json::parse(f.default_value);
    } catch (const std::exception&) {
      ADD_FAILURE() << what << ": key '" << f.key << "': default '" << f.default_value
                    << "' is no JSON value; the table needs a sample() for it";
      return nullptr;
    }
  }
  static const std::map<std::string, Json> byType = {
      {"number", 1.0},     {"integer", 1},          {"boolean", true},
      {"string", "x"},     {"numbers", {1.0, 2.0}}, {"vec3", {0.0, 0.0, 1.0}},
      {"strings", {"x"}},  {"object", Json::object()}};
  auto it = byType.find(f.type);
  if (it != byType.end()) return it->second;
  ADD_FAILURE() << what << ": required key '" << f.key << "' of form '" << f.type << "' needs a sample()";
  return nullptr;
}

/// Splits "a: b: c" into {"a", "b", "c"}.
std::vector<std::string> pathOf(const std::string& key) {
  std::vector<std::string> p;
  std::size_t start = 0;
  for (;;) {
    const std::size_t at = key.find(": ", start);
    p.push_back(key.substr(start, at - start));
    if (at == std::string::npos) return p;
    start = at + 2;
  }
}

/// The listed keys of a type, by object path ("" = top level): key -> its path.
struct Listed {
  std::map<std::string, std::set<std::string>> keys;  ///< object path ("a: b") -> keys listed in it
  Json params = Json::object();                       ///< every listed key with its sample
};

/// Lists `fields` (only those under `prefix`, with it removed) and builds the params.
Listed listedKeys(const std::vector<FieldInfo>& fields, const std::string& what, const std::string& prefix = "",
                  Json base = Json::object()) {
  Listed l;
  l.params = std::move(base);
  for (const auto& f : fields) {
    if (f.key.compare(0, prefix.size(), prefix) != 0) continue;
    EXPECT_FALSE(f.meaning.empty()) << what << " " << f.key;
    EXPECT_FALSE(f.default_value.empty()) << what << " " << f.key;
    const std::vector<std::string> path = pathOf(f.key.substr(prefix.size()));
    std::string parent;
    Json* node = &l.params;
    for (std::size_t i = 0; i + 1 < path.size(); ++i) {
      parent += (parent.empty() ? "" : ": ") + path[i];
      if (!node->contains(path[i]) || !(*node)[path[i]].is_object()) (*node)[path[i]] = Json::object();
      node = &(*node)[path[i]];
    }
    l.keys[parent].insert(path.back());
    if (!node->contains(path.back())) {
      Json v = sampleOf(f, what);
      if (!v.is_null()) (*node)[path.back()] = std::move(v);  // else reported; the key is left out
    } else if (f.type == "object" && !(*node)[path.back()].is_object()) {
      (*node)[path.back()] = Json::object();
    }
  }
  return l;
}

/// The reader of the object at `path` under `r`.
ParamReader childAt(const ParamReader& r, const std::string& path) {
  if (path.empty()) return r;
  ParamReader c = r;
  for (const auto& k : pathOf(path)) c = c.child(k);
  return c;
}

/// The keys asked for equal the listed keys, at every listed object level.
void expectQueriedIsListed(const ParamReader& r, const Listed& l, const std::string& what) {
  for (const auto& [path, keys] : l.keys) {
    const Json* node = &r.json();
    bool present = true;
    if (!path.empty())
      for (const auto& k : pathOf(path)) {
        if (!node->contains(k)) { present = false; break; }
        node = &node->at(k);
      }
    if (!present || !node->is_object()) continue;
    std::set<std::string> asked;
    for (const auto& k : childAt(r, path).queriedKeys())
      if (k.empty() || k[0] != '_') asked.insert(k);
    for (const auto& k : asked)
      EXPECT_TRUE(keys.count(k)) << what << ": the factory reads '" << (path.empty() ? "" : path + ": ") << k
                                 << "', which `vdyn list` does not print";
    for (const auto& k : keys)
      EXPECT_TRUE(asked.count(k)) << what << ": `vdyn list` prints '" << (path.empty() ? "" : path + ": ") << k
                                  << "', which the factory never reads";
  }
}

std::string unknownKeyError(const std::function<void(const ParamReader&)>& make, const Json& params) {
  Json extra = params;
  extra["zz_not_a_key"] = 1;
  return errorOf([&] {
    const ParamReader r = ParamReader::fromJson(extra, "t.json");
    make(r);
    r.requireAllKeysRead();
  });
}

/// The accept / read / reject checks for one type.
void checkType(const std::string& what, const std::vector<FieldInfo>& fields,
               const std::function<void(const ParamReader&)>& make) {
  SCOPED_TRACE(what);
  const Listed l = listedKeys(fields, what);
  const ParamReader r = ParamReader::fromJson(l.params, "t.json");
  const std::string made = errorOf([&] {
    make(r);
    r.requireAllKeysRead();
  });
  ASSERT_EQ(made, "(no error)") << what << " with every listed key: " << l.params.dump();
  expectQueriedIsListed(r, l, what);
  const std::string e = unknownKeyError(make, l.params);
  EXPECT_NE(e.find("zz_not_a_key: unknown key"), std::string::npos) << what << ": " << e;
}

/// The data file each vehicle type is checked with (its geometry must be real).
const std::map<std::string, std::string>& vehicleData() {
  static const std::map<std::string, std::string> m = {
      {"fourws", "appendix_a.json"}, {"wheeled", "appendix_a.json"}, {"bicycle", "bicycle.json"},
      {"quarter_car", "quarter_car.json"}};
  return m;
}

}  // namespace

TEST(RegistryKeys, EveryPluginAndAnalysisAcceptsExactlyItsListedKeys) {
  const PluginRegistry& reg = standardRegistry();
  int checked = 0;
  for (PluginKind kind : allKinds()) {
    if (kind == PluginKind::Vehicle) continue;
    for (const auto& type : reg.known(kind)) {
      const std::string what = std::string(toKey(kind)) + " " + type;
      const TypeInfo& info = reg.info(kind, type);
      EXPECT_FALSE(info.summary.empty()) << what;
      if (kind == PluginKind::Analysis) {
        checkType(what, info.fields, [&](const ParamReader& r) { reg.createAnalysis(type, r, "t.json: analysis"); });
      } else {
        checkType(what, info.fields, [&](const ParamReader& r) {
          PluginSpec spec{"p", r, {}, &reg};
          reg.create(kind, type, spec, "t.json: plugins[0]");
        });
      }
      ++checked;
    }
  }
  EXPECT_GE(checked, 15);
}

TEST(RegistryKeys, EveryChoiceAcceptsExactlyItsListedKeys) {
  const PluginRegistry& reg = standardRegistry();
  const KrTable table = KrTable::fromFile(resolveDataPath("kr_table.json"));
  const std::vector<std::string> families = reg.choiceFamilies();
  EXPECT_EQ(families, (std::vector<std::string>{"anti_roll_bar_template", "rear_steer_strategy",
                                                "sensitivity_method", "steering_command", "steering_template",
                                                "suspension_template"}))
      << "a new choice family: add its Base and Context to this test";
  for (const auto& family : families)
    for (const auto& type : reg.knownChoices(family)) {
      const std::string what = family + " " + type;
      const TypeInfo& info = reg.choiceInfo(family, type);
      EXPECT_FALSE(info.summary.empty()) << what;
      checkType(what, info.fields, [&](const ParamReader& r) {
        if (family == "steering_command")
          reg.createChoice<SteeringCommand>(family, type, r, NoContext{}, "t.json");
        else if (family == "rear_steer_strategy")
          reg.createChoice<RearSteerStrategy, RearSteerContext>(family, type, r,
                                                                RearSteerContext{LinearBicycleParams{}, &table}, "t.json");
        else if (family == "sensitivity_method")
          reg.createChoice<SensitivityMethod, SensitivitySettings>(family, type, r, SensitivitySettings{}, "t.json");
        else if (family == "suspension_template")
          reg.createChoice<Suspension>(family, type, r, NoContext{}, "t.json");
        else if (family == "anti_roll_bar_template")
          reg.createChoice<AntiRollBar>(family, type, r, NoContext{}, "t.json");
        else if (family == "steering_template")
          reg.createChoice<RackAndPinion>(family, type, r, NoContext{}, "t.json");
      });
    }
}

TEST(RegistryKeys, EveryVehicleReadsExactlyItsListedDataKeys) {
  const PluginRegistry& reg = standardRegistry();
  for (const auto& type : reg.known(PluginKind::Vehicle)) {
    SCOPED_TRACE(type);
    const auto file = vehicleData().find(type);
    ASSERT_NE(file, vehicleData().end()) << "vehicle " << type << ": add its data file to this test";
    const TypeInfo& info = reg.info(PluginKind::Vehicle, type);
    // Scene keys (read by the scene loader): data, overrides, initial_speed_m_s.
    std::set<std::string> scene;
    for (const auto& f : info.fields)
      if (f.key.rfind("data: ", 0) != 0) scene.insert(f.key);
    EXPECT_EQ(scene, (std::set<std::string>{"data", "overrides", "initial_speed_m_s"})) << type;
    // The data keys: the real file, with every listed key it lacks at its default.
    const Json data = ParamReader::fromFile(file->second).json();
    const Listed l = listedKeys(info.fields, "vehicle " + type, "data: ", data);
    auto make = [&](const ParamReader& r) { reg.createVehicle(type, VehicleSpec{type, r, &reg}, "t.json: vehicle"); };
    const ParamReader r = ParamReader::fromJson(l.params, file->second);
    const std::string made = errorOf([&] {
      make(r);
      r.requireAllKeysRead();
    });
    ASSERT_EQ(made, "(no error)") << type;
    expectQueriedIsListed(r, l, "vehicle " + type);
    const std::string e = unknownKeyError(make, l.params);
    EXPECT_NE(e.find("zz_not_a_key: unknown key"), std::string::npos) << type << ": " << e;
  }
}

TEST(RegistryKeys, WheeledListsItsTemplatesAndForwardDynamics) {
  const TypeInfo& info = standardRegistry().info(PluginKind::Vehicle, "wheeled");
  std::map<std::string, std::string> defaults;
  for (const auto& f : info.fields) defaults[f.key] = f.default_value;
  EXPECT_EQ(defaults["data: axles"], "required");
  for (const char* t : {"double_wishbone", "double_wishbone_reduced"}) {
    std::set<std::string> keys;
    for (const auto& f : standardRegistry().choiceInfo("suspension_template", t).fields) keys.insert(f.key);
    EXPECT_EQ(keys, (std::set<std::string>{"bodies", "joints", "spring", "left", "hardpoints_m", "tie_rod",
                                           "camber_rad", "toe_in_rad"}))
        << t;
  }
  std::set<std::string> strut;
  for (const auto& f : standardRegistry().choiceInfo("suspension_template", "macpherson_strut").fields) strut.insert(f.key);
  EXPECT_EQ(strut, (std::set<std::string>{"bodies", "hardpoints_m", "tie_rod", "camber_rad", "toe_in_rad", "spring"}));
  EXPECT_EQ(defaults["data: formulation"], "\"auto\"");
  EXPECT_EQ(defaults["data: gravity_m_per_s2"], "9.81");
}

TEST(RegistryKeys, NestedObjectKeysAreListedWithTheirUnitsAndDefaults) {
  // The tire plugin's params object: its own table, listed as "params: <key>".
  const TypeInfo& gim = standardRegistry().info(PluginKind::ForceElement, "gim");
  bool found = false;
  for (const auto& f : gim.fields)
    if (f.key == "params: radial_stiffness_N_per_m") {
      found = true;
      EXPECT_EQ(f.unit, "N/m");
      EXPECT_EQ(Json::parse(f.default_value).get<double>(), TireVerticalParams{}.radial_stiffness_N_per_m);
    }
  EXPECT_TRUE(found);
}
