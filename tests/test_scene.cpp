// Scene files, the registry of every kind, field tables, strict keys,
// overrides, plugin libraries: numbers and named errors.
#include <gtest/gtest.h>

#include <mutex>
#include <thread>

#include "test_util.h"
#include "vdyn/analyses/analyses.h"
#include "vdyn/core/fields.h"
#include "vdyn/core/key_path.h"
#include "vdyn/core/log.h"
#include "vdyn/core/plugin_library.h"
#include "vdyn/forces/body_force.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/speed/speed_hold.h"
#include "vdyn/rear_steer/rear_steer.h"
#include "vdyn/sensitivity/sensitivity.h"
#include "vdyn/steering/steering.h"
#include "vdyn/vehicles/wheeled_vehicle.h"
#include "vdyn/vehicles/quarter_car.h"
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

TEST(KeyPath, ParsesFormatsAndRoundTrips) {
  const KeyPath k = KeyPath::parse("plugins.front_steer.command.steps[1].change_rad", "w");
  ASSERT_EQ(k.parts().size(), 6u);
  EXPECT_EQ(k.parts()[3].text, "steps");
  EXPECT_FALSE(k.parts()[3].bracketed);
  EXPECT_EQ(k.parts()[4].text, "1");
  EXPECT_TRUE(k.parts()[4].bracketed);
  EXPECT_EQ(k.format(), "plugins.front_steer.command.steps[1].change_rad");
  for (const char* t : {"a", "a.b[2].c", "a[0][1]", "a.2.c", "x_y-z.q[10]"})
    EXPECT_EQ(KeyPath::parse(KeyPath::parse(t, "w").format(), "w"), KeyPath::parse(t, "w")) << t;
  EXPECT_EQ(KeyPath::parse("a[0][1]", "w").format(), "a[0][1]");
  EXPECT_TRUE(KeyPath::parse("vehicle.data.x", "w").startsWith(KeyPath::parse("vehicle.data", "w")));
  EXPECT_FALSE(KeyPath::parse("vehicle.datax", "w").startsWith(KeyPath::parse("vehicle.data", "w")));
  EXPECT_EQ(KeyPath::parse("vehicle.data.a[1]", "w").tail(2).under(KeyPath::parse("vehicle.overrides", "w")).format(),
            "vehicle.overrides.a[1]");
  EXPECT_EQ(KeyPath::ofKeys({"a", "b"}).child("c").format(), "a.b.c");
  EXPECT_EQ(errorOf([] { KeyPath::parse("a..b", "f.json: set"); }),
            "f.json: set: key path 'a..b': empty part (expected e.g. a.b[2].c)");
  EXPECT_EQ(errorOf([] { KeyPath::parse("a[x]", "w"); }),
            "w: key path 'a[x]': index [x] is not a number (expected e.g. a.b[2].c)");
  EXPECT_EQ(errorOf([] { KeyPath::parse("a[1", "w"); }), "w: key path 'a[1': unclosed or empty index (expected e.g. a.b[2].c)");
  EXPECT_EQ(errorOf([] { KeyPath::parse("[1]", "w"); }), "w: key path '[1]': an index must follow a key (expected e.g. a.b[2].c)");
  EXPECT_EQ(errorOf([] { KeyPath::parse("a[1]b", "w"); }), "w: key path 'a[1]b': text after an index (expected e.g. a.b[2].c)");
  EXPECT_EQ(errorOf([] { KeyPath::parse("a.", "w"); }), "w: key path 'a.': ends with '.' (expected e.g. a.b[2].c)");
  EXPECT_EQ(errorOf([] { KeyPath::parse("a b", "w"); }), "w: key path 'a b': character ' ' (expected e.g. a.b[2].c)");
  EXPECT_EQ(errorOf([] { KeyPath::parse("", "w"); }), "w: key path '': empty (expected e.g. a.b[2].c)");
}

TEST(KeyPath, FindsAndSetsByIndexOrNameWithOneErrorFormat) {
  Json j = R"({"plugins": [{"name": "a", "steps": [{"v": 1}, {"v": 2}]}, {"name": "7", "v": 3}],
               "out": {"chassis.yaw_rad": 0.5, "chassis": {"x": 1}}, "n": 4})"_json;
  auto find = [&](const char* t) { return KeyPath::parse(t, "w").find(j); };
  EXPECT_EQ(*find("plugins.a.steps[1].v"), 2);
  EXPECT_EQ(*find("plugins.a.steps.1.v"), 2);   // digits at an array: an index
  EXPECT_EQ(*find("plugins[1].v"), 3);
  EXPECT_EQ(*find("plugins.1.v"), 3);           // ... not the element named "7"
  EXPECT_EQ(*find("out.chassis.yaw_rad"), 0.5);  // a key with a dot: the longest key wins
  EXPECT_EQ(*find("out.chassis.x"), 1);
  EXPECT_EQ(find("plugins.a.steps[2]"), nullptr);
  EXPECT_EQ(find("plugins.b"), nullptr);
  EXPECT_EQ(find("n.x"), nullptr);
  EXPECT_EQ(find("out[0]"), nullptr);

  KeyPath::parse("plugins.a.steps[0].v", "w").set(j, 1.5, "w");
  KeyPath::parse("plugins.1.new.deep", "w").set(j, "x", "w");  // missing keys are created
  EXPECT_EQ(j["plugins"][0]["steps"][0]["v"], 1.5);
  EXPECT_EQ(j["plugins"][1]["new"]["deep"], "x");
  EXPECT_EQ(errorOf([&] { KeyPath::parse("plugins.a.steps[5].v", "s.json").set(j, 1, "s.json"); }),
            "s.json: key path 'plugins.a.steps[5].v': plugins.a.steps has 2 elements, no [5]");
  EXPECT_EQ(errorOf([&] { KeyPath::parse("plugins.b.v", "s.json").get(j, "s.json"); }),
            "s.json: key path 'plugins.b.v': plugins has no element named 'b'");
  EXPECT_EQ(errorOf([&] { KeyPath::parse("n.x", "s.json").set(j, 1, "s.json"); }),
            "s.json: key path 'n.x': n is 4, not an object or array");
  EXPECT_EQ(errorOf([&] { KeyPath::parse("out.nothing", "s.json").get(j, "s.json"); }),
            "s.json: key path 'out.nothing': out has no key 'nothing'");
  EXPECT_EQ(errorOf([&] { KeyPath::parse("out[0]", "s.json").set(j, 1, "s.json"); }),
            "s.json: key path 'out[0]': out is an object, not an array: no [0]");
}

// --set with an index into a steering command's "steps": the changed step
// reaches the built plugin (its command at the end is the sum of the steps).
TEST(Override, IndexIntoAnArrayReachesTheBuiltPlugin) {
  const SceneDescription s = smallScene(R"({
    "plugins": [
      {"type": "steering", "name": "front_steer", "attach": "front_axle",
       "command": {"type": "steps", "steps": [{"start_time_s": 0.0, "duration_s": 0.05, "change_rad": 0.02},
                                              {"start_time_s": 0.08, "duration_s": 0.05, "change_rad": 0.01}]}},
      {"type": "speed_hold", "name": "speed_hold", "attach": "chassis", "speed_m_s": 10}],
    "outputs": ["chassis.yaw_rate_rad_s", "front_steer.command_rad"]})"_json);
  const Json base = runScene(s);
  EXPECT_DOUBLE_EQ(base["final"]["front_steer.command_rad"].get<double>(), 0.02 + 0.01);
  const SceneDescription changed =
      s.withOverrides({Override::parse("plugins.front_steer.command.steps[1].change_rad=0.04")});
  EXPECT_EQ(changed.json()["plugins"][0]["command"]["steps"][1]["change_rad"], 0.04);
  const Json run = runScene(changed);
  EXPECT_DOUBLE_EQ(run["final"]["front_steer.command_rad"].get<double>(), 0.02 + 0.04);
  EXPECT_GT(std::abs(run["final"]["chassis.yaw_rate_rad_s"].get<double>()),
            std::abs(base["final"]["chassis.yaw_rate_rad_s"].get<double>()));
  EXPECT_EQ(errorOf([&] { s.withOverrides({Override::parse("plugins.front_steer.command.steps[5].change_rad=0.04")}); }),
            "small.json: key path 'plugins.front_steer.command.steps[5].change_rad': "
            "plugins.front_steer.command.steps has 2 elements, no [5]");
  EXPECT_EQ(errorOf([&] { Override::parse("plugins.front_steer..x=1"); }),
            "--set 'plugins.front_steer..x=1': key path 'plugins.front_steer..x': empty part (expected e.g. a.b[2].c)");
}

// A sensitivity design parameter with an index: its nominal is read and each
// design is built through the same KeyPath (the steering command's steps[1]).
TEST(SceneDesign, ParameterWithAnIndexIsReadAndSet) {
  const SceneDescription s = smallScene(R"({
    "plugins": [
      {"type": "steering", "name": "front_steer", "attach": "front_axle",
       "command": {"type": "steps", "steps": [{"start_time_s": 0.0, "duration_s": 0.05, "change_rad": 0.02},
                                              {"start_time_s": 0.08, "duration_s": 0.05, "change_rad": 0.01}]}},
      {"type": "speed_hold", "name": "speed_hold", "attach": "chassis", "speed_m_s": 10}],
    "outputs": ["front_steer.command_rad"]})"_json);
  const std::string path = "plugins.front_steer.command.steps[1].change_rad";
  const auto params = SceneDesign::parametersOf(s, {path});
  ASSERT_EQ(params.size(), 1u);
  EXPECT_EQ(params[0].name, path);
  EXPECT_EQ(params[0].nominal, 0.01);
  EXPECT_EQ(params[0].scale, 0.01);
  const SceneDesign design(s, params);
  const auto inst = design.build({0.04});
  SimTK::State st = inst->makeInitialState();
  st.setTime(0.2);  // after both steps
  EXPECT_DOUBLE_EQ(inst->getScene().evalOutput("front_steer.command_rad", st), 0.02 + 0.04);
  EXPECT_EQ(errorOf([&] { SceneDesign::parametersOf(s, {"plugins.front_steer.command.steps[2].change_rad"}); }),
            "small.json: sensitivity parameter: key path 'plugins.front_steer.command.steps[2].change_rad': "
            "plugins.front_steer.command.steps has 2 elements, no [2]");
}

TEST(Registry, EveryKindIsRegisteredAndDocumented) {
  const PluginRegistry& r = standardRegistry();
  EXPECT_EQ(r.known(PluginKind::Vehicle), (std::vector<std::string>{"bicycle", "fourws", "quarter_car", "wheeled"}));
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
  // The tire's field table is BrushTireParams::fields(): same keys, defaults of BrushTireParams{}.
  const TypeInfo& gim = r.info(PluginKind::ForceElement, "gim");
  bool found = false;
  for (const auto& f : gim.fields)
    if (f.key == "params: cornering_stiffness_N_per_rad") {
      found = true;
      EXPECT_EQ(f.unit, "N/rad");
      EXPECT_EQ(std::stod(f.default_value), BrushTireParams{}.cornering_stiffness_N_per_rad);
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
// final state of a scene run equals, bit for bit, that of WheeledVehicle with
// addAxleSteering and SpeedHoldPlugin added by hand in the same order.
TEST(SceneFile, TransientEqualsTheSameCompositionInCxxBitForBit) {
  const SceneDescription s = smallScene();
  const Json summary = runScene(s);
  WheeledVehicle car(WheeledVehicleParams::fromFile("appendix_a.json"));
  car.addAxleSteering("front_steer", "front", std::make_shared<HoldCommand>(0.05));
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

// Choices inside plugins and analyses are registered names: a steering command
// registered the way a plugin library does (addChoice) is found by the steering
// plugin of a scene built from that registry; the families are listed; errors
// name the family, the type and the known ones.
namespace {
class ConstCommand : public SteeringCommand {
 public:
  explicit ConstCommand(double a) : a_(a) {}

 protected:
  SteerCommandValue DoCalc(double) const override { return {a_, 0, 0}; }

 private:
  double a_;
};
}  // namespace

TEST(Registry, ChoicesAreRegisteredNamesThatPluginsOfASceneFind) {
  PluginRegistry r = makeStandardRegistry();
  r.addChoice<SteeringCommand>(
      "steering_command", "fixture_const",
      [](const ParamReader& p, const NoContext&) { return std::make_unique<ConstCommand>(p.number("angle_rad")); },
      {"test: a constant angle", {{"angle_rad", "rad", "required", "angle"}}});
  Json j = smallScene().json();
  j["plugins"][0]["command"] = R"({"type": "fixture_const", "angle_rad": 0.03})"_json;
  const BuiltScene b = SceneDescription::fromJson(j, "small.json", r).build();
  const SimTK::State s = b.makeInitialState();
  EXPECT_EQ(b.scene().evalOutput("front_steer.command_rad", s), 0.03);
  EXPECT_NEAR(b.scene().evalOutput("front_steer.angle_rad", s), 0.03, 1e-9);  // the knuckles follow it
  // Not in the standard registry: the same scene names an unknown command.
  const std::string unknown = errorOf([&] { SceneDescription::fromJson(j, "small.json", standardRegistry()).build(); });
  EXPECT_TRUE(contains(unknown, "small.json") &&
              contains(unknown, "unknown steering command 'fixture_const'; known: chirp, hold, ramp, sine, sine_with_dwell, "
                                "smooth_step, steps, table"))
      << unknown;
  EXPECT_EQ(r.choiceFamilies(),
            (std::vector<std::string>{"anti_roll_bar_template", "rear_steer_strategy", "sensitivity_method",
                                      "steering_command", "steering_template", "suspension_template"}));
  EXPECT_EQ(r.knownChoices("sensitivity_method"),
            (std::vector<std::string>{"fd_central", "fd_forward", "mixed", "reference"}));
  EXPECT_EQ(r.choiceInfo("steering_command", "smooth_step").fields.at(1).key, "final_rad");
  EXPECT_EQ(errorOf([&] {
              r.addChoice<SteeringCommand>(
                  "steering_command", "hold",
                  [](const ParamReader&, const NoContext&) { return std::make_unique<ConstCommand>(0); }, {});
            }),
            "steering command 'hold' is already registered");
  EXPECT_EQ(errorOf([&] {
              r.addChoice<RearSteerStrategy, RearSteerContext>(
                  "steering_command", "x",
                  [](const ParamReader&, const RearSteerContext&) { return std::make_unique<TwoWsStrategy>(); }, {});
            }),
            "steering command 'x': the family was registered with another interface");
  EXPECT_EQ(makeRearSteerStrategy("2ws", LinearBicycleParams{}, nullptr, &r)->name(), "2ws");
  EXPECT_EQ(makeSensitivityMethod("mixed", {}, &r)->name(), "mixed");
}

// The concrete vehicle of a built scene, for code that needs its own API.
TEST(SceneFile, VehicleAsGivesTheConcreteVehicleOrANamedError) {
  BuiltScene b = smallScene().build();
  EXPECT_EQ(&b.vehicleAs<WheeledVehicle>().getScene(), &b.scene());
  EXPECT_EQ(errorOf([&] { b.vehicleAs<QuarterCar>(); }), "vehicle 'fourws' is not a vdyn::QuarterCar");
}

// body_force: the rise, hold and fall of its scale (closed form).
TEST(BodyForce, ScaleRisesHoldsAndFalls) {
  BodyForceParams p;
  p.force_N = SimTK::Vec3(1, 0, 0);
  p.start_time_s = 1.0;
  p.rise_time_s = 0.5;
  p.duration_s = 2.0;
  EXPECT_EQ(p.scale(0.9), 0.0);
  EXPECT_DOUBLE_EQ(p.scale(1.25), 0.5);
  EXPECT_EQ(p.scale(2.0), 1.0);
  EXPECT_DOUBLE_EQ(p.scale(3.75), 0.5);  // falling: 3.5 .. 4.0
  EXPECT_EQ(p.scale(4.5), 0.0);
  p.rise_time_s = 0;
  p.duration_s = 0;
  EXPECT_EQ(p.scale(0.999), 0.0);
  EXPECT_EQ(p.scale(1.0), 1.0);
  EXPECT_EQ(p.scale(100.0), 1.0);
}

// Static equilibrium of the quarter car through the scene path: the chassis
// slides vertically, so the tire carries the whole weight plus a downward
// body_force on the chassis: Fz = m g + F (force balance, closed form).
TEST(SceneAnalyses, StaticEquilibriumTireCarriesWeightPlusBodyForce) {
  auto scene = [](double F) {
    Json j = R"({
      "vehicle": {"type": "quarter_car", "data": "quarter_car.json"},
      "analysis": {"type": "static_equilibrium", "ineffective_bodies": ["wheel"]}
    })"_json;
    if (F != 0)
      j["plugins"] = Json::array({{{"type", "body_force"}, {"name", "push"}, {"attach", "chassis"},
                                   {"force_N", {0.0, 0.0, -F}}}});
    return SceneDescription::fromJson(j, "qc.json", standardRegistry());
  };
  const Json plain = runScene(scene(0)), pushed = runScene(scene(300));  // (1000 N bottoms the linkage)
  const double mg = 226.0 * 9.81;  // quarter_car.json: 200 kg chassis + 26 kg corner, g = 9.81 m/s^2
  // The solver stops at a generalized-force residual of 1e-6 N (its default).
  EXPECT_NEAR(plain["equilibrium"]["tire.Fz_N"].get<double>(), mg, 1e-5);
  EXPECT_NEAR(pushed["equilibrium"]["tire.Fz_N"].get<double>(), mg + 300, 1e-5);
  EXPECT_EQ(pushed["equilibrium"]["push.Fz_N"].get<double>(), -300);
  EXPECT_LT(pushed["equilibrium"]["chassis.z_m"].get<double>(), plain["equilibrium"]["chassis.z_m"].get<double>());
}

// The libraries' diagnostics go to the log sink the program installs
// (vdyn/core/log.h), never to stderr by themselves, and do not change results:
// the static equilibrium's Newton iterations are logged at debug level only
// while a sink is installed, and the equilibrium is the same bit for bit.
TEST(Log, SinkReceivesDiagnosticsAndResultsDoNotChange) {
  const SceneDescription s = SceneDescription::fromJson(R"({
      "vehicle": {"type": "quarter_car", "data": "quarter_car.json"},
      "analysis": {"type": "static_equilibrium", "ineffective_bodies": ["wheel"]}})"_json,
                                                        "qc.json", standardRegistry());
  EXPECT_FALSE(logEnabled(LogLevel::Debug));  // the default: no sink
  const Json quiet = runScene(s);
  std::vector<std::string> lines;
  std::mutex m;
  setLogSink([&](LogLevel level, const std::string& text) {
    std::lock_guard<std::mutex> lock(m);
    lines.push_back(std::string(logLevelName(level)) + " " + text);
  });
  EXPECT_TRUE(logEnabled(LogLevel::Debug));
  const Json logged = runScene(s);
  setLogSink(nullptr);
  EXPECT_FALSE(logEnabled(LogLevel::Debug));
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines[0].rfind("debug equilibrium: iteration 0 alpha ", 0), 0u) << lines[0];
  EXPECT_EQ(logged["equilibrium"], quiet["equilibrium"]);
  const std::size_t n = lines.size();
  runScene(s);
  EXPECT_EQ(lines.size(), n);  // removed: nothing more arrives
  setLogSink([&](LogLevel, const std::string& text) { lines.push_back(text); }, LogLevel::Warning);
  EXPECT_FALSE(logEnabled(LogLevel::Debug));  // below the minimum
  setLogSink(nullptr);
  EXPECT_EQ(logFormat("%d %.3f %s", 7, 0.5, "x"), "7 0.500 x");
}

// Continuation in the speed hold's adjustable speed finds, at its first value,
// the steady state the steady_state analysis solves directly (same equations
// and start: equal to the solver's precision), and a higher yaw rate at 12 m/s.
TEST(SceneAnalyses, ContinuationAgreesWithSteadyState) {
  Json j = smallScene().json();
  j["analysis"] = R"({"type": "steady_state"})"_json;
  const Json ss = runScene(SceneDescription::fromJson(j, "small.json", standardRegistry()));
  j["analysis"] = R"({"type": "continuation", "plugin": "speed_hold", "key": "speed_m_s", "values": [10, 12]})"_json;
  const Json co = runScene(SceneDescription::fromJson(j, "small.json", standardRegistry()));
  ASSERT_EQ(co["converged_points"].get<int>(), 2);
  const double r10 = co["points"][0]["outputs"]["chassis.yaw_rate_rad_s"].get<double>();
  const double r12 = co["points"][1]["outputs"]["chassis.yaw_rate_rad_s"].get<double>();
  EXPECT_NEAR(r10, ss["steady"]["chassis.yaw_rate_rad_s"].get<double>(), 1e-9);
  EXPECT_GT(r12, r10);
  EXPECT_EQ(co["points"][1]["value"].get<double>(), 12.0);
}

// A reduced 4WS vehicle built from a scene file (formulation "reduced" as a
// vehicle override, steering plugins from the registry) starts from the same
// state as the same composition in C++ (WheeledVehicle::addAxleSteering): the
// constrained copy it is assembled from carries the scene's steering holds
// (front 0.05 rad, rear 0.02 rad), so positions and speeds agree bit for bit.
TEST(SceneFile, ReducedFourWsStartsLikeTheCxxCompositionWithItsSteeringHolds) {
  Json extra = R"({"vehicle": {"overrides": {"formulation": "reduced"}}})"_json;
  Json j = smallScene(extra).json();
  j["plugins"].insert(j["plugins"].begin() + 1, R"({"type": "steering", "name": "rear_steer", "attach": "rear_axle",
                                                    "command": {"type": "hold", "angle_rad": 0.02}})"_json);
  const BuiltScene built = SceneDescription::fromJson(j, "small.json", standardRegistry()).build();
  ASSERT_TRUE(built.vehicleAs<WheeledVehicle>().isReduced());
  const SimTK::State ss = built.makeInitialState();

  WheeledVehicleParams p = WheeledVehicleParams::fromFile("appendix_a.json");
  p.formulation = "reduced";
  WheeledVehicle car(p);
  car.addAxleSteering("front_steer", "front", std::make_shared<HoldCommand>(0.05));
  car.addAxleSteering("rear_steer", "rear", std::make_shared<HoldCommand>(0.02));
  car.updScene().addPlugin(std::make_unique<SpeedHoldPlugin>("speed_hold", "chassis", 10.0));
  const SimTK::State cs = car.makeInitialState(10.0);

  ASSERT_EQ(ss.getNQ(), cs.getNQ());
  ASSERT_EQ(ss.getNU(), cs.getNU());
  double dq = 0, du = 0;
  for (int i = 0; i < ss.getNQ(); ++i) dq = std::max(dq, std::abs(ss.getQ()[i] - cs.getQ()[i]));
  for (int i = 0; i < ss.getNU(); ++i) du = std::max(du, std::abs(ss.getU()[i] - cs.getU()[i]));
  EXPECT_EQ(dq, 0.0);
  EXPECT_EQ(du, 0.0);
  // The knuckles' steering coordinates are the holds (q = [s, delta]).
  for (int c : {RF, LF}) EXPECT_NEAR(car.reducedCorner(c).knuckle.getOneQ(cs, 1), 0.05, 1e-9);
  for (int c : {RR, LR}) EXPECT_NEAR(car.reducedCorner(c).knuckle.getOneQ(cs, 1), 0.02, 1e-9);
}

// The continuation's lead values start the branch and are not reported: the
// points after them are the same solves as in a run that reports them (bit for
// bit); the branch check's output must exist and its bound exceed 1.
TEST(SceneAnalyses, ContinuationLeadValuesAreSolvedButNotReported) {
  // scenes/steady_sweep.json: 10 m/s, rear at 0.25 of the front, branch check on the yaw rate.
  const SceneDescription sweep = SceneDescription::fromFile("scenes/steady_sweep.json", standardRegistry());
  const Json all = runScene(sweep.withOverrides({{"analysis.lead_values", Json::array()},
                                                 {"analysis.values", {0.0, 1e-4, 0.01, 0.02}}}));
  const Json led = runScene(sweep.withOverrides({{"analysis.lead_values", {0.0, 1e-4}},
                                                 {"analysis.values", {0.01, 0.02}}}));
  ASSERT_EQ(all["total_points"].get<int>(), 4);
  ASSERT_EQ(all["converged_points"].get<int>(), 4);
  ASSERT_EQ(led["total_points"].get<int>(), 2);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(led["points"][i]["value"], all["points"][i + 2]["value"]);
    EXPECT_EQ(led["points"][i]["outputs"]["chassis.yaw_rate_rad_s"].get<double>(),
              all["points"][i + 2]["outputs"]["chassis.yaw_rate_rad_s"].get<double>());
    EXPECT_EQ(led["points"][i]["iterations"], all["points"][i + 2]["iterations"]);
  }
  EXPECT_EQ(led["stable_points"].get<int>(), 2);  // 10 m/s, 0.6 and 1.1 deg: stable
  EXPECT_EQ(led["largest_stable_value"].get<double>(), 0.02);
  EXPECT_EQ(led["last_converged_point"]["value"].get<double>(), 0.02);
  EXPECT_GT(led["last_converged_point"]["outputs"]["chassis.yaw_rate_rad_s"].get<double>(), 0.0);  // turning left

  EXPECT_TRUE(contains(errorOf([&] { sweep.withOverride("analysis.branch_max_change_factor", 1.0).build(); }),
                       "analysis.branch_max_change_factor: must be > 1, got 1"));
  EXPECT_TRUE(contains(errorOf([&] { runScene(sweep.withOverride("analysis.branch_output", "chassis.yaw_rat")); }),
                       "chassis.yaw_rat"));
}

// The continuation's limit (issue 22): at 20 m/s (scenes/steady_sweep.json,
// rear at 0.25 of the front) the branch in the front angle ends; its fold,
// located by pseudo-arclength continuation, lies within the grid step above
// the last converged point (the old limit) and below the first failed value;
// the points continued past it are unstable (an eigenvalue with positive real
// part), and the grid points beyond it are "beyond_fold".
TEST(SceneAnalyses, ContinuationLimitIsTheFoldAndPassesIt) {
  const SceneDescription sweep = SceneDescription::fromFile(
      "scenes/steady_sweep.json", standardRegistry(),
      {{"vehicle.initial_speed_m_s", 20.0}, {"plugins.speed_hold.speed_m_s", 20.0}});
  const Json j = runScene(sweep);
  const double last = j["last_converged_point"]["value"].get<double>();
  double failed = 0;
  for (const auto& p : j["points"])
    if (!p["converged"].get<bool>()) {
      failed = p["value"].get<double>();
      EXPECT_EQ(p["status"], "beyond_fold");
      break;
    }
  ASSERT_GT(failed, last);
  const Json& fold = j["limit"]["fold"];
  ASSERT_FALSE(fold.is_null()) << j["limit"].dump();
  const double v = fold["value"].get<double>();
  std::printf("20 m/s: fold at %.6f deg (a_y %.4f m/s^2, bracket %.1e rad), last converged %.2f deg, failed %.2f deg; "
              "%d steps, %d rejected\n",
              v * 180 / SimTK::Pi, fold["lateral_acceleration_m_s2"].get<double>(), fold["bracket"].get<double>(),
              last * 180 / SimTK::Pi, failed * 180 / SimTK::Pi, j["limit"]["steps"].get<int>(),
              j["limit"]["rejected_steps"].get<int>());
  EXPECT_GT(v, last);
  EXPECT_LT(v, failed);
  EXPECT_EQ(j["limit_value"].get<double>(), v);
  EXPECT_TRUE(fold["located"].get<bool>());
  EXPECT_LE(fold["bracket"].get<double>(), 1e-7);  // fold_tolerance
  // At the fold of the fixed-steer dynamics a real eigenvalue crosses zero.
  EXPECT_LE(std::abs(fold["eigenvalues"][0][0].get<double>()), 1e-3);
  int past = 0;
  for (const auto& p : j["limit"]["points"]) {
    if (!p["past_fold"].get<bool>()) {
      EXPECT_TRUE(p["stable"].get<bool>());
      continue;
    }
    ++past;
    EXPECT_FALSE(p["stable"].get<bool>());
    EXPECT_GT(p["least_damped_eigenvalue"][0].get<double>(), 0);
    EXPECT_LT(p["value"].get<double>(), v);
    EXPECT_GT(p["lateral_acceleration_m_s2"].get<double>(), fold["lateral_acceleration_m_s2"].get<double>());
  }
  EXPECT_EQ(past, 3);  // past_fold_points
}

TEST(SceneAnalyses, SteadyStateStartIsStraightOrGiven) {
  const SceneDescription ch3 = SceneDescription::fromFile("scenes/ch3_steady_state.json", standardRegistry());
  EXPECT_TRUE(contains(errorOf([&] { ch3.withOverride("analysis.start", "foo").build(); }),
                       "analysis.start: must be \"straight\" or \"given\", got \"foo\""));
  // Both starts land on the same steady state here (to the solver's precision).
  const Json straight = runScene(ch3), given = runScene(ch3.withOverride("analysis.start", "given"));
  const double rs = straight["steady"]["chassis.yaw_rate_rad_s"].get<double>();
  const double rg = given["steady"]["chassis.yaw_rate_rad_s"].get<double>();
  EXPECT_NEAR(rs, rg, 1e-10 * rg);
  EXPECT_GT(straight["homotopy_steps"].get<int>(), 0);
  EXPECT_FALSE(given.contains("homotopy_steps"));
}

// A transient that leaves its regime (the ch3 turn at 15 m/s spins) is a
// result: its summary lists the spin-out with the time and value it was first
// seen (beyond the stated 0.35 rad, no larger than the run's peak side slip),
// and the run ends normally; listed in analysis.events.fatal it ends the run
// with the event's line naming the option; the 10 m/s turn has no event.
TEST(SceneFile, TransientRecordsItsRegimeEventsAndAFatalOneEndsTheRun) {
  PluginRegistry& reg = standardRegistry();
  const SceneDescription base = SceneDescription::fromFile("scenes/ch3_transient.json", reg);
  const SceneDescription fast = base.withOverrides({{"vehicle.initial_speed_m_s", 15.0},
                                                    {"plugins.speed_hold.speed_m_s", 15.0},
                                                    {"analysis.t_end_s", 14.0}});
  RunOptions opt;  // no files
  opt.plots = false;
  const Json s = runScene(fast, opt);
  ASSERT_EQ(s.at("events").size(), 1u) << s.at("events").dump();
  const Json& e = s.at("events")[0];
  EXPECT_EQ(e.at("kind"), "spin_out");
  EXPECT_EQ(e.at("object"), "chassis.side_slip_rad");
  EXPECT_GT(e.at("time_s").get<double>(), 1.5);
  EXPECT_LT(e.at("time_s").get<double>(), 14.0);
  EXPECT_GT(std::abs(e.at("value").get<double>()), 0.35);
  EXPECT_LE(std::abs(e.at("value").get<double>()), s.at("peak_abs").at("chassis.side_slip_rad").get<double>() + 1e-12);
  EXPECT_NE(e.at("message").get<std::string>().find("spin_out at t = "), std::string::npos);
  std::printf("15 m/s: %s\n", e.at("message").get<std::string>().c_str());

  const std::string fatal = errorOf([&] {
    runScene(fast.withOverride("analysis.events.fatal", Json::array({"spin_out"})), opt);
  });
  EXPECT_NE(fatal.find("spin_out at t = "), std::string::npos) << fatal;
  EXPECT_NE(fatal.find("analysis.events.fatal"), std::string::npos) << fatal;
  const std::string unknown = errorOf([&] {
    runScene(fast.withOverride("analysis.events.fatal", Json::array({"spin"})), opt);
  });
  EXPECT_NE(unknown.find("unknown event kind 'spin' (known: spin_out, rollover, left_path, lift_off)"),
            std::string::npos)
      << unknown;

  const Json slow = runScene(base.withOverride("analysis.t_end_s", 3.0), opt);
  EXPECT_TRUE(slow.at("events").empty());
}
