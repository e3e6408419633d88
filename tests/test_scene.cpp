// Scene files, the registry of every kind, field tables, strict keys,
// overrides, plugin libraries: numbers and named errors.
#include <gtest/gtest.h>

#include <thread>

#include "test_util.h"
#include "vdyn/analyses/analyses.h"
#include "vdyn/core/fields.h"
#include "vdyn/core/plugin_library.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/speed/speed_hold.h"
#include "vdyn/vehicles/fourws.h"
#include "vdyn/vehicles/standard_registry.h"

using namespace vdyn;
using vdyn::test::errorOf;

namespace {
bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

/// A small 4WS scene (hold steering, speed hold) with `extra` merged over it.
SceneDescription smallScene(const Json& extra = Json::object()) {
  Json j = R"({
    "name": "small",
    "vehicle": {"type": "fourws", "data": "appendix_a.json", "initial_speed_m_s": 10},
    "plugins": [
      {"type": "steering", "name": "front_steer", "attach": "front_axle",
       "command": {"type": "hold", "angle_rad": 0.05}},
      {"type": "speed_hold", "name": "speed_hold", "attach": "chassis", "speed_m_s": 10}
    ],
    "outputs": ["chassis.yaw_rate_rad_s"],
    "analysis": {"type": "transient", "t_end_s": 0.2, "report_interval_s": 0.05,
                 "integrator": {"method": "rk_merson", "accuracy": 1e-5}}
  })"_json;
  j.merge_patch(extra);
  return SceneDescription::fromJson(j, "small.json", standardRegistry());
}
}  // namespace

TEST(ParamReaderStrict, UnknownKeyNamedWithNearestHint) {
  const ParamReader r = ParamReader::fromJson(Json{{"sped_m_s", 2.0}, {"mass_kg", 1.0}, {"_note", "x"}}, "f.json");
  EXPECT_EQ(r.numberOr("speed_m_s", 1.0), 1.0);
  r.number("mass_kg");
  EXPECT_EQ(r.unreadKeys(), std::vector<std::string>{"f.json: sped_m_s: unknown key (did you mean 'speed_m_s'?)"});
  EXPECT_EQ(errorOf([&] { r.requireAllKeysRead(); }), "f.json: sped_m_s: unknown key (did you mean 'speed_m_s'?)");
  r.markAllRead();
  EXPECT_TRUE(r.unreadKeys().empty());
}

TEST(ParamReaderStrict, NestedObjectsReadThroughChildAreChecked) {
  const ParamReader r =
      ParamReader::fromJson(Json{{"a", {{"x_m", 1.0}, {"zzzz", 2.0}}}, {"b", 3.0}, {"raw", {{"q", 1}}}}, "f.json");
  r.child("a").number("x_m");
  r.number("b");
  r.has("raw");  // read raw (json()): its inside is the reader's business
  EXPECT_EQ(r.unreadKeys(), std::vector<std::string>{"f.json: a.zzzz: unknown key"});
}

TEST(FieldTable, ReadsWritesAndDescribesFromOneTable) {
  struct P {
    double length_m = 2.5;
    int count = 3;
    std::string name = "x";
  };
  const auto t = FieldTable<P>()
                     .number("length_m", &P::length_m, "m", "a length")
                     .integer("count", &P::count, "", "a count")
                     .string("name", &P::name, "a name", true);
  const auto info = t.describe();
  ASSERT_EQ(info.size(), 3u);
  EXPECT_EQ(info[0].key, "length_m");
  EXPECT_EQ(info[0].unit, "m");
  EXPECT_EQ(info[0].default_value, "2.5");
  EXPECT_EQ(info[2].default_value, "required");
  const ParamReader r = ParamReader::fromJson(Json{{"length_m", 4.0}, {"name", "y"}}, "p.json");
  const P p = t.read(r);
  EXPECT_EQ(p.length_m, 4.0);
  EXPECT_EQ(p.count, 3);
  EXPECT_EQ(p.name, "y");
  EXPECT_EQ(t.write(p)["length_m"], 4.0);
  EXPECT_EQ(errorOf([&] { t.read(ParamReader::fromJson(Json::object(), "p.json")); }), "p.json: name: missing key");
}

TEST(Override, ParsesValuesAndAddressesArraysByNameOrIndex) {
  Json j = R"({"plugins": [{"name": "a", "v": 1}, {"name": "b", "v": 2}], "x": {"y": 1}})"_json;
  applyOverride(j, Override::parse("plugins.b.v=3.5"), "s.json");
  applyOverride(j, Override::parse("plugins.0.v=[1,2]"), "s.json");
  applyOverride(j, Override::parse("x.z=word"), "s.json");
  EXPECT_EQ(j["plugins"][1]["v"], 3.5);
  EXPECT_EQ(j["plugins"][0]["v"], Json::parse("[1,2]"));
  EXPECT_EQ(j["x"]["z"], "word");
  EXPECT_EQ(errorOf([&] { Override::parse("novalue"); }), "--set 'novalue': expected key.path=value");
  EXPECT_TRUE(contains(errorOf([&] { applyOverride(j, Override::parse("plugins.c.v=1"), "s.json"); }),
                       "plugins has no element named 'c'"));
  EXPECT_TRUE(contains(errorOf([&] { applyOverride(j, Override::parse("x.y.w=1"), "s.json"); }),
                       "x.y is 1, not an object or array"));
}

TEST(Registry, EveryKindIsRegisteredAndDocumented) {
  const PluginRegistry& r = standardRegistry();
  EXPECT_EQ(r.known(PluginKind::Vehicle), (std::vector<std::string>{"bicycle", "fourws", "quarter_car"}));
  EXPECT_TRUE(r.has(PluginKind::ForceElement, "gim"));
  EXPECT_TRUE(r.has(PluginKind::Constraint, "steering"));
  EXPECT_TRUE(r.has(PluginKind::Constraint, "speed_hold"));
  EXPECT_TRUE(r.has(PluginKind::Controller, "path_control"));
  EXPECT_TRUE(r.has(PluginKind::Analysis, "transient"));
  for (PluginKind k : allKinds())
    for (const auto& type : r.known(k)) {
      const TypeInfo& info = r.info(k, type);
      EXPECT_FALSE(info.summary.empty()) << toKey(k) << " " << type;
      EXPECT_FALSE(info.fields.empty()) << toKey(k) << " " << type;
      for (const auto& f : info.fields) {
        EXPECT_FALSE(f.key.empty()) << type;
        EXPECT_FALSE(f.meaning.empty()) << type << " " << f.key;
        EXPECT_FALSE(f.default_value.empty()) << type << " " << f.key;
      }
    }
  // The tire's field table is TireParams::fields(): same keys, defaults of TireParams{}.
  const TypeInfo& gim = r.info(PluginKind::ForceElement, "gim");
  bool found = false;
  for (const auto& f : gim.fields)
    if (f.key == "params: cornering_stiffness_N_per_rad") {
      found = true;
      EXPECT_EQ(f.unit, "N/rad");
      EXPECT_EQ(std::stod(f.default_value), TireParams{}.cornering_stiffness_N_per_rad);
    }
  EXPECT_TRUE(found);
  EXPECT_EQ(errorOf([&] { r.createAnalysis("bogus", ParamReader::fromJson(Json::object(), "s"), "s.json: analysis.type"); })
                .substr(0, 48),
            "s.json: analysis.type: unknown analysis 'bogus';");
}

TEST(SceneFile, CheckReportsEveryErrorAtOnce) {
  const SceneDescription s = smallScene(R"({
      "colour": "red",
      "outputs": ["chassis.yaw_rate_rad_s", "chassis.nope"],
      "analysis": {"t_end_s": -1}
    })"_json);
  Json j = s.json();
  j["plugins"].push_back(R"({"type": "steering", "name": "rear_steer", "attach": "rear_axel",
                            "command": {"type": "hold", "angle_rad": 0}})"_json);
  j["plugins"].push_back(R"({"type": "warp_drive", "name": "w"})"_json);
  j["plugins"][1]["speed_ms"] = 3;
  const auto errors = SceneDescription::fromJson(j, "small.json", standardRegistry()).check();
  std::string all;
  for (const auto& e : errors) all += e + "\n";
  EXPECT_EQ(errors.size(), 6u) << all;
  EXPECT_TRUE(contains(all, "small.json: colour: unknown key")) << all;
  EXPECT_TRUE(contains(all, "small.json: outputs[1]: the scene has no output 'chassis.nope'")) << all;
  EXPECT_TRUE(contains(all, "small.json: analysis.t_end_s must be positive, got -1")) << all;
  EXPECT_TRUE(contains(all, "small.json: plugins[2]: fourws vehicle has no attachment 'rear_axel'")) << all;
  EXPECT_TRUE(contains(all, "small.json: plugins[3].type: unknown plugin 'warp_drive'")) << all;
  EXPECT_TRUE(contains(all, "small.json: plugins[1].speed_ms: unknown key")) << all;
  EXPECT_TRUE(smallScene().check().empty());
}

TEST(SceneFile, BuildThrowsTheFirstErrorNamingFileAndKey) {
  EXPECT_EQ(errorOf([&] { smallScene(R"({"vehicle": {"type": "tank"}})"_json).build(); })
                .substr(0, 58),
            "small.json: vehicle.type: unknown vehicle 'tank'; known: b");
  EXPECT_EQ(errorOf([&] { smallScene(R"({"vehicle": {"data": "nope.json"}})"_json).build(); }).substr(0, 48),
            "small.json: data file 'nope.json' not found (loo");
}

// The scene path composes the same Simbody system as the C++ builders: the
// final state of a scene run equals, bit for bit, that of FourWsVehicle with
// addAxleSteering and SpeedHoldPlugin added by hand in the same order.
TEST(SceneFile, TransientEqualsTheSameCompositionInCxxBitForBit) {
  const SceneDescription s = smallScene();
  const Json summary = runScene(s);
  FourWsVehicle car(FourWsParams::fromFile("appendix_a.json"));
  car.addAxleSteering("front_steer", true, std::make_shared<HoldCommand>(0.05));
  car.updScene().addPlugin(std::make_unique<SpeedHoldPlugin>("speed_hold", "chassis", 10.0));
  SimTK::State st = car.makeInitialState(10.0);
  SimulationSettings sim;
  sim.t_end_s = 0.2;
  sim.report_interval_s = 0.05;
  sim.integrator.accuracy = 1e-5;
  Recorder rec(car.getScene(), {"chassis.yaw_rate_rad_s"});
  const RunSummary run = simulate(car.getScene(), st, sim, &rec);
  EXPECT_EQ(summary["final"]["chassis.yaw_rate_rad_s"].get<double>(),
            car.getScene().evalOutput("chassis.yaw_rate_rad_s", st));
  EXPECT_EQ(summary["final"]["speed_hold.force_N"].get<double>(), car.getScene().evalOutput("speed_hold.force_N", st));
  EXPECT_EQ(summary["run"]["steps"].get<int>(), run.steps);
  EXPECT_EQ(summary["vehicle"]["dof"].get<int>(), car.degreesOfFreedom(st));
  EXPECT_GT(std::abs(summary["final"]["chassis.yaw_rate_rad_s"].get<double>()), 1e-3);  // it turns
  EXPECT_EQ(summary["scene"], "small");
  EXPECT_EQ(summary["analysis"], "transient");
}

TEST(SceneFile, OverridesChangeTheRunAndSeparateThreadsAgree) {
  const SceneDescription s = smallScene();
  const SceneDescription faster = s.withOverride("vehicle.initial_speed_m_s", 12.0)
                                      .withOverride("plugins.speed_hold.speed_m_s", 12.0);
  Json a, b, c;
  std::thread t1([&] { a = runScene(s); });
  std::thread t2([&] { b = runScene(faster); });
  t1.join();
  t2.join();
  c = runScene(s);
  EXPECT_EQ(a["final"]["chassis.yaw_rate_rad_s"], c["final"]["chassis.yaw_rate_rad_s"]);
  EXPECT_NE(a["final"]["chassis.yaw_rate_rad_s"], b["final"]["chassis.yaw_rate_rad_s"]);
  EXPECT_NEAR(b["final"]["chassis.forward_speed_m_s"].get<double>(), 12.0, 0.05);
  EXPECT_NEAR(a["final"]["chassis.forward_speed_m_s"].get<double>(), 10.0, 0.05);
}

TEST(PluginLibrary, LoadsAndRegistersAFactoryUsableFromAScene) {
  PluginRegistry r = makeStandardRegistry();
  loadPluginLibrary(VDYN_FIXTURE_GOOD, r);
  loadPluginLibrary(VDYN_FIXTURE_GOOD, r);  // a second load is a no-op
  ASSERT_TRUE(r.has(PluginKind::ForceElement, "fixture_push"));
  EXPECT_EQ(r.info(PluginKind::ForceElement, "fixture_push").fields.at(1).unit, "N");
  Json j = smallScene().json();
  j["plugins"].push_back(R"({"type": "fixture_push", "name": "push", "attach": "chassis", "force_N": 500})"_json);
  const Json pushed = runScene(SceneDescription::fromJson(j, "small.json", r));
  const Json plain = runScene(smallScene());
  // The speed hold takes the push: its force changes by about -500 N.
  EXPECT_NEAR(pushed["final"]["speed_hold.force_N"].get<double>() - plain["final"]["speed_hold.force_N"].get<double>(),
              -500, 25);
}

TEST(PluginLibrary, NamedErrors) {
  PluginRegistry r;
  EXPECT_EQ(errorOf([&] { loadPluginLibrary("/nonexistent/libx.so", r); }),
            "plugin library '/nonexistent/libx.so': not found");
  EXPECT_TRUE(contains(errorOf([&] { loadPluginLibrary(VDYN_FIXTURE_NO_ENTRY, r); }),
                       "has no vdyn_plugin_abi_version() entry point"));
  const std::string abi = errorOf([&] { loadPluginLibrary(VDYN_FIXTURE_BAD_ABI, r); });
  EXPECT_TRUE(contains(abi, "built for plugin ABI version " + std::to_string(VDYN_PLUGIN_ABI_VERSION + 100) +
                                ", this vdyn has version " + std::to_string(VDYN_PLUGIN_ABI_VERSION)))
      << abi;
}
