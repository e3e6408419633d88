// Bounded input (nesting depth, file size, a sweep's variation count) and
// derived scenes merging plugins by name: named errors and resolved lists.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "test_util.h"
#include "vdyn/core/params.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/core/sweep.h"
#include "vdyn/vehicles/standard_registry.h"

namespace fs = std::filesystem;
using namespace vdyn;
using vdyn::test::errorOf;

namespace {
std::string freshDir(const std::string& name) {
  const std::string d = std::string(VDYN_TEST_OUT_DIR) + "/input_" + name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void writeText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

std::string readText(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

struct Ran {
  int rc = -1;
  std::string out, err;
};

Ran runVdyn(const std::string& args, const std::string& dir) {
  const std::string cmd = std::string("'") + VDYN_BIN + "' " + args + " > '" + dir + "/stdout.txt' 2> '" + dir +
                          "/stderr.txt'";
  const int st = std::system(cmd.c_str());
  Ran r;
  r.rc = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  r.out = readText(dir + "/stdout.txt");
  r.err = readText(dir + "/stderr.txt");
  return r;
}

std::string nested(std::size_t n) { return std::string(n, '[') + std::string(n, ']'); }

/// The plugin names of a resolved scene, in order.
std::string pluginNames(const SceneDescription& s) {
  std::string names;
  for (const Json& p : s.json().at("plugins")) names += (names.empty() ? "" : ",") + p.at("name").get<std::string>();
  return names;
}
}  // namespace

// --- bounded input ----------------------------------------------------------------
TEST(BoundedInput, DeepNestingIsANamedError) {
  EXPECT_EQ(errorOf([] { parseJsonText(nested(200000), "data file 'deep.json'"); }),
            "data file 'deep.json' nests 200000 arrays/objects deep (line 1, column 101 passes the limit of 100)");
  // Brackets in strings and comments do not count; 100 levels are accepted.
  EXPECT_NO_THROW(parseJsonText("// [[[[\n{\"a\": \"" + std::string(500, '[') + "\", \"b\": " + nested(99) + "}", "x"));
  EXPECT_EQ(errorOf([] { parseJsonText(R"({"a": )" + nested(101) + "}", "scene 'x.json'"); }),
            "scene 'x.json' nests 102 arrays/objects deep (line 1, column 106 passes the limit of 100)");
  // A --set value too.
  EXPECT_EQ(errorOf([] { Override::parse("analysis.t_end_s=" + nested(5000), "--set"); }),
            "--set 'analysis.t_end_s=...' nests 5000 arrays/objects deep (line 1, column 101 passes the limit of 100)");
}

TEST(BoundedInput, OversizedFileIsANamedError) {
  const std::string d = freshDir("oversized"), path = d + "/big.json";
  { std::ofstream(path) << "{}"; }
  fs::resize_file(path, kMaxJsonFileBytes + 1);  // sparse: no 64 MiB written
  EXPECT_EQ(errorOf([&] { readJsonFile(path); }),
            "data file '" + path + "' is 67108865 bytes (limit 67108864 bytes, 64 MiB)");
  // A device has no size to check first: reading stops at the limit.
  EXPECT_EQ(errorOf([] { readJsonFile("/dev/zero"); }),
            "data file '/dev/zero' is more than 67108864 bytes (the limit, 64 MiB)");
}

TEST(BoundedInput, VdynCheckOnADeeplyNestedSceneExitsOneNotACrash) {
  const std::string d = freshDir("deep_scene");
  // A scene object holding 200,000 nested arrays: before the limit, exit 139
  // (a segmentation fault) in both check and run.
  writeText(d + "/deep.json", "{\"name\": " + nested(200000) + "}");
  const Ran r = runVdyn("check '" + d + "/deep.json'", d);
  EXPECT_EQ(r.rc, 1);
  EXPECT_EQ(r.err, "vdyn check: error: data file '" + d +
                       "/deep.json' nests 200001 arrays/objects deep (line 1, column 109 passes the limit of 100)\n");
  const Ran s = runVdyn("run '" + d + "/deep.json' --no-plots --out '" + d + "/out'", d);
  EXPECT_EQ(s.rc, 1);
  EXPECT_NE(s.err.find("nests 200001 arrays/objects deep"), std::string::npos) << s.err;
}

TEST(BoundedInput, TenToTheTenVariationsAreRefusedBeforeAllocation) {
  const Json grid = Json::parse(R"({"scene": "s.json", "variations": [{"grid": [
      {"key": "a", "from": 0, "to": 1, "count": 100}, {"key": "b", "from": 0, "to": 1, "count": 100},
      {"key": "c", "from": 0, "to": 1, "count": 100}, {"key": "d", "from": 0, "to": 1, "count": 100},
      {"key": "e", "from": 0, "to": 1, "count": 100}]}]})");
  EXPECT_EQ(errorOf([&] { SweepDescription::fromJson(grid, "big.sweep.json:", ""); }),
            "big.sweep.json: variations[0].grid: 100 x 100 x 100 x 100 x 100 = 10000000000 variations; the limit is 1000000 "
            "variations per sweep");
  // Blocks add up: 600,000 + 600,000 passes the limit in the second block.
  const Json two = Json::parse(R"({"scene": "s.json", "variations": [
      {"monte_carlo": {"samples": 600000, "seed": 1, "ranges": {"a": [0, 1]}}},
      {"latin_hypercube": {"samples": 600000, "seed": 1, "ranges": {"a": [0, 1]}}}]})");
  EXPECT_EQ(errorOf([&] { SweepDescription::fromJson(two, "big.sweep.json:", ""); }),
            "big.sweep.json: variations[1].latin_hypercube.samples: 600000 samples make 1200000 variations in all; "
            "the limit is 1000000 variations per sweep");
  // Through vdyn sweep: exit 1, the count and the limit named.
  const std::string d = freshDir("big_sweep");
  writeText(d + "/big.sweep.json", R"({"scene": "scenes/ch3_steady_state.json", "variations": [{"grid": [
      {"key": "analysis.time_s", "from": 1, "to": 2, "count": 100000},
      {"key": "vehicle.initial_speed_m_s", "from": 5, "to": 10, "count": 100000}]}],
      "collect": ["newton_iterations"]})");
  const Ran r = runVdyn("sweep '" + d + "/big.sweep.json' --quiet --no-plots --out '" + d + "/out'", d);
  EXPECT_EQ(r.rc, 1);
  EXPECT_NE(r.err.find("100000 x 100000 = 10000000000 variations; the limit is 1000000 variations per sweep"),
            std::string::npos)
      << r.err;
}

// --- derived scenes: plugins merged by name ---------------------------------------
namespace {
/// A base scene with three plugins and a derived one with `derived` merged over it.
SceneDescription derivedScene(const std::string& dirName, const std::string& derived) {
  const std::string d = freshDir(dirName);
  writeText(d + "/base.json", R"({
    "name": "base",
    "vehicle": {"type": "fourws", "data": "appendix_a.json", "initial_speed_m_s": 10},
    "plugins": [
      {"type": "steering", "name": "front_steer", "attach": "front_axle", "command": {"type": "hold", "angle_rad": 0.05}},
      {"type": "steering", "name": "rear_steer", "attach": "rear_axle", "command": {"type": "hold", "angle_rad": 0}},
      {"type": "speed_hold", "name": "speed_hold", "attach": "chassis", "speed_m_s": 10}
    ],
    "analysis": {"type": "transient", "t_end_s": 0.1}
  })");
  writeText(d + "/derived.json", R"({"based_on": "base.json", )" + derived + "}");
  return SceneDescription::fromFile(d + "/derived.json", standardRegistry());
}
}  // namespace

TEST(DerivedScene, AnEntryWithABaseNameMergesOverIt) {
  const SceneDescription s = derivedScene("merge", R"("plugins": [{"name": "front_steer", "command": {"angle_rad": 0.02}}])");
  EXPECT_EQ(pluginNames(s), "front_steer,rear_steer,speed_hold");
  EXPECT_EQ(s.json()["plugins"][0]["command"], Json::parse(R"({"type": "hold", "angle_rad": 0.02})"));
  EXPECT_EQ(s.json()["plugins"][0]["attach"], "front_axle");
  EXPECT_TRUE(s.check().empty());
}

TEST(DerivedScene, ACommandOfAnotherTypeReplacesTheBlock) {
  // A merge would keep the hold's angle_rad, an unknown key of a smooth step.
  const SceneDescription s = derivedScene("retype", R"("plugins": [{"name": "front_steer", "command":
      {"type": "smooth_step", "initial_rad": 0, "final_rad": 0.03, "start_time_s": 0.2, "duration_s": 0.5}}])");
  EXPECT_EQ(s.json()["plugins"][0]["command"],
            Json::parse(R"({"type": "smooth_step", "initial_rad": 0, "final_rad": 0.03, "start_time_s": 0.2, "duration_s": 0.5})"));
  EXPECT_EQ(s.json()["plugins"][0]["attach"], "front_axle");  // the entry itself is still merged
  EXPECT_TRUE(s.check().empty());
  // null deletes a member (RFC 7396), also inside a replaced block.
  const SceneDescription n = derivedScene("null", R"("plugins": [{"name": "speed_hold", "speed_m_s": null}])");
  EXPECT_FALSE(n.json()["plugins"][2].contains("speed_m_s"));
}

TEST(DerivedScene, ANewNameIsAppended) {
  const SceneDescription s = derivedScene(
      "append", R"("plugins": [{"type": "body_force", "name": "push", "attach": "chassis", "force_N": [0, 100, 0]}])");
  EXPECT_EQ(pluginNames(s), "front_steer,rear_steer,speed_hold,push");
}

TEST(DerivedScene, RemoveTrueRemovesOne) {
  const SceneDescription s = derivedScene("remove", R"("plugins": [{"name": "rear_steer", "remove": true}])");
  EXPECT_EQ(pluginNames(s), "front_steer,speed_hold");
  EXPECT_EQ(errorOf([] { derivedScene("remove_missing", R"("plugins": [{"name": "nope", "remove": true}])"); }),
            std::string(VDYN_TEST_OUT_DIR) +
                "/input_remove_missing/derived.json: plugins[0].remove: the base scene has no plugin 'nope' to remove");
}

TEST(DerivedScene, ReplacingTheListNeedsPluginsReplace) {
  const SceneDescription s = derivedScene(
      "replace", R"("plugins_replace": true, "plugins": [{"type": "speed_hold", "name": "hold", "attach": "chassis", "speed_m_s": 10}])");
  EXPECT_EQ(pluginNames(s), "hold");
  EXPECT_FALSE(s.json().contains("plugins_replace"));
  const std::string where = std::string(VDYN_TEST_OUT_DIR) + "/input_unnamed/derived.json";
  EXPECT_EQ(errorOf([] { derivedScene("unnamed", R"("plugins": [{"type": "speed_hold", "speed_m_s": 10}])"); }),
            where + ": plugins[0]: a derived scene's plugin entry needs a \"name\" (it merges over the base's plugin "
                    "of that name, or is added; \"plugins_replace\": true replaces the base's list), got "
                    "{\"speed_m_s\":10,\"type\":\"speed_hold\"}");
}

TEST(DerivedScene, CheckResolvedPrintsThePluginList) {
  derivedScene("resolved", R"("plugins": [{"name": "rear_steer", "remove": true},
      {"type": "body_force", "name": "push", "attach": "chassis", "force_N": [0, 100, 0]}])");
  const std::string d = std::string(VDYN_TEST_OUT_DIR) + "/input_resolved";
  const Ran r = runVdyn("check --resolved '" + d + "/derived.json'", d);
  EXPECT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("vdyn check: " + d + "/derived.json: plugins: front_steer (steering) speed_hold (speed_hold) "
                       "push (body_force)\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("\"force_N\": ["), std::string::npos);  // the resolved JSON
}

// A run's summary.json records what ran: the scene file and its plugins as
// resolved, so a plugin inherited from the base (here the speed hold) is on
// record; vdyn run prints the same list.
TEST(DerivedScene, TheRunSummaryRecordsTheResolvedPlugins) {
  derivedScene("summary_plugins", R"("plugins": [{"name": "rear_steer", "remove": true},
      {"type": "body_force", "name": "push", "attach": "chassis", "force_N": [0, 100, 0]}],
      "analysis": {"type": "transient", "t_end_s": 0.01, "report_interval_s": 0})");
  const std::string d = std::string(VDYN_TEST_OUT_DIR) + "/input_summary_plugins";
  const Ran r = runVdyn("run '" + d + "/derived.json' --no-plots --out '" + d + "/out'", d);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("  plugins: front_steer (steering), speed_hold (speed_hold), push (body_force)\n"),
            std::string::npos)
      << r.out;
  std::ifstream in(d + "/out/summary.json");
  const Json summary = Json::parse(in);
  EXPECT_EQ(summary["scene_file"], d + "/derived.json");
  EXPECT_EQ(summary["plugins"], Json::parse(R"([{"name": "front_steer", "type": "steering"},
      {"name": "speed_hold", "type": "speed_hold"}, {"name": "push", "type": "body_force"}])"));
}

// --- consistency checks before a run ----------------------------------------------
TEST(Consistency, SpeedHoldAgainstInitialSpeedIsNamedByCheckAndRun) {
  const std::string d = freshDir("speed_hold");
  const Ran c = runVdyn("check scenes/ch3_transient.json --set plugins.speed_hold.speed_m_s=20", d);
  EXPECT_EQ(c.rc, 1);
  const std::string why = "speed_hold 'speed_hold': speed_m_s = 20 m/s differs from the vehicle's initial speed 10 m/s "
                          "(vehicle.initial_speed_m_s): a speed hold cannot change the speed at t = 0; set both to "
                          "the same value\n";
  EXPECT_EQ(c.err.substr(0, 19), "vdyn check: error: ");
  EXPECT_NE(c.err.find("ch3_transient.json: plugins: " + why), std::string::npos) << c.err;
  EXPECT_EQ(std::count(c.err.begin(), c.err.end(), '\n'), 1) << c.err;
  const Ran r = runVdyn("run scenes/ch3_transient.json --no-plots --set plugins.speed_hold.speed_m_s=20 --out '" + d +
                            "/out'",
                        d);
  EXPECT_EQ(r.rc, 1);
  EXPECT_NE(r.err.find(why), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("projectU"), std::string::npos) << r.err;
  // Both changed together: ok.
  EXPECT_EQ(runVdyn("check scenes/ch3_transient.json --set plugins.speed_hold.speed_m_s=20 "
                    "--set vehicle.initial_speed_m_s=20", d).rc, 0);
}

// --- messages ---------------------------------------------------------------------
TEST(Messages, OneRootCauseOneLineWithItsOutputsSummarised) {
  const std::string d = freshDir("one_cause");
  // front_steer is not built: its two outputs in "outputs" were two more lines
  // of about 45 output names each.
  const Ran c = runVdyn("check scenes/ch3_transient.json --set plugins.front_steer.attach=nowhere", d);
  EXPECT_EQ(c.rc, 1);
  EXPECT_EQ(std::count(c.err.begin(), c.err.end(), '\n'), 1) << c.err;
  EXPECT_NE(c.err.find("plugins[0]: fourws vehicle has no attachment 'nowhere'; known: chassis, front_axle, lf, lr, "
                       "rear_axle, rf, rr, wheels (and 2 outputs of plugin 'front_steer' named in \"outputs\")\n"),
            std::string::npos)
      << c.err;
}

TEST(Messages, UnknownTypeNamesTheKindsAndPluginOption) {
  const std::string d = freshDir("unknown_type");
  const Ran c = runVdyn("check scenes/ch3_transient.json --set plugins.speed_hold.type=warp_drive", d);
  EXPECT_EQ(c.rc, 1);
  EXPECT_NE(c.err.find("unknown constraint plugin 'warp_drive'; known: speed_hold, steering; no constraint library "
                       "registers it: load the one that does with --plugin LIB.so or the scene's \"plugin_libraries\""),
            std::string::npos)
      << c.err;
  // Without "kind": every kind that could provide it is named.
  const std::string scene = d + "/kindless.json";
  writeText(scene, R"({"based_on": "scenes/ch3_transient.json",
      "plugins": [{"name": "push", "type": "warp_drive", "attach": "chassis"}]})");
  const Ran k = runVdyn("check '" + scene + "'", d);
  EXPECT_NE(k.err.find("unknown plugin 'warp_drive'; known: "), std::string::npos) << k.err;
  EXPECT_NE(k.err.find("; no force_element, constraint or controller library registers it: load the one that does "
                       "with --plugin LIB.so or the scene's \"plugin_libraries\""),
            std::string::npos)
      << k.err;
  const Ran v = runVdyn("check scenes/ch3_transient.json --set vehicle.type=hovercraft", d);
  EXPECT_NE(v.err.find("unknown vehicle 'hovercraft'; known: "), std::string::npos) << v.err;
  EXPECT_NE(v.err.find("; no vehicle library registers it: load the one that does with --plugin LIB.so"),
            std::string::npos)
      << v.err;
  const Ran p = runVdyn("check scenes/ch3_transient.json --plugin libnope.so", d);
  EXPECT_EQ(p.rc, 1);
  EXPECT_NE(p.err.find("plugin library 'libnope.so': not found (looked for /"), std::string::npos) << p.err;
}

TEST(Messages, MissingFilesListTheFoldersSearched) {
  const std::string d = freshDir("missing");
  const Ran c = runVdyn("check scenes/ch3_transient.json --set vehicle.data=nope.json", d);
  EXPECT_EQ(c.rc, 1);
  EXPECT_NE(c.err.find("data file 'nope.json' not found (looked in "), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("/scenes, "), std::string::npos) << c.err;  // the scene's folder, then the data path
}

TEST(Messages, OnePathRuleForASweepsScene) {
  // The scene next to the working directory, not next to the sweep file: not
  // found (as a vehicle data file would not be), naming the folders searched.
  const std::string d = freshDir("path_rule");
  fs::create_directories(d + "/sweeps");
  writeText(d + "/mine.json", R"({"based_on": "scenes/ch3_steady_state.json"})");
  writeText(d + "/sweeps/s.sweep.json", R"({"scene": "mine.json", "variations": [{"list": [{"analysis.time_s": 1}]}],
      "collect": ["newton_iterations"]})");
  // Run from `d` (the working directory holds mine.json).
  const std::string cmd = "cd '" + d + "' && '" + std::string(VDYN_BIN) +
                          "' sweep sweeps/s.sweep.json --quiet --no-plots --out out > o.txt 2> e.txt";
  const int st = std::system(cmd.c_str());
  const std::string err = readText(d + "/e.txt");
  EXPECT_EQ(WEXITSTATUS(st), 1);
  EXPECT_NE(err.find("s.sweep.json: scene: scene file 'mine.json' not found (looked in sweeps, "), std::string::npos)
      << err;
  // Next to the sweep file it is found.
  writeText(d + "/sweeps/mine.json", R"({"based_on": "scenes/ch3_steady_state.json"})");
  EXPECT_EQ(WEXITSTATUS(std::system(cmd.c_str())), 0) << readText(d + "/e.txt");
}

// `vdyn list outputs SCENE` and `vdyn list attachments SCENE` print what the
// built scene provides: every output with its unit and stage (the recorded
// ones marked), every attachment with its bindings; without a scene, a named
// error.
TEST(ListScene, OutputsAndAttachmentsOfABuiltScene) {
  const std::string d = freshDir("list_scene");
  const std::string scene = std::string(VDYN_DATA_DIR) + "/scenes/ch3_transient.json";
  const Ran o = runVdyn("list outputs '" + scene + "'", d);
  ASSERT_EQ(o.rc, 0) << o.err;
  EXPECT_NE(o.out.find("* chassis.yaw_rate_rad_s"), std::string::npos) << o.out;
  auto lineOf = [](const std::string& text, const std::string& key) {
    const std::size_t i = text.find(key);
    if (i == std::string::npos) return std::string();
    const std::size_t b = text.rfind('\n', i), e = text.find('\n', i);
    return text.substr(b == std::string::npos ? 0 : b + 1, e - (b == std::string::npos ? 0 : b + 1));
  };
  const std::string an = lineOf(o.out, "chassis.path_normal_accel_m_s2");
  EXPECT_NE(an.find("m/s^2"), std::string::npos) << an;
  EXPECT_NE(an.find("Acceleration"), std::string::npos) << an;
  EXPECT_NE(o.out.find("tire_rf.Fz_N"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("speed_hold.force_N"), std::string::npos) << o.out;
  const Ran a = runVdyn("list attachments '" + scene + "'", d);
  ASSERT_EQ(a.rc, 0) << a.err;
  EXPECT_NE(a.out.find("front_axle       chassis = chassis, knuckles = rf.knuckle,lf.knuckle"), std::string::npos)
      << a.out;
  const Ran e = runVdyn("list outputs", d);
  EXPECT_EQ(e.rc, 1);
  EXPECT_NE(e.err.find("vdyn list outputs SCENE: no scene file given"), std::string::npos) << e.err;
}
