// The sweep runner (vdyn/core/sweep.h) on a synthetic run function: variations,
// strict sweep files, thread results equal to serial byte for byte, failed
// rows, resume. The same on real scenes: tests/CMakeLists.txt (vdyn sweep).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

#include "vdyn/core/key_path.h"
#include "vdyn/core/named_outcome.h"
#include "vdyn/core/scene_file.h"
#include "vdyn/core/sweep.h"

using namespace vdyn;

namespace {

std::string tempDir(const std::string& name) {
  const std::string d = std::filesystem::temp_directory_path().string() + "/vdyn_test_sweep_" + name + "_" +
                        std::to_string(::getpid());
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

std::string readFile(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

/// A deterministic computation whose cost grows with "n" (runs differ 10x),
/// failing where "fail" is true.
Json synthetic(const SweepDescription&, const Variation& v) {
  const double x = v.find("a.x")->get<double>();
  const int n = v.find("n") ? v.find("n")->get<int>() : 1000;
  if (v.find("fail") && v.find("fail")->get<bool>()) throw Error("synthetic failure at a.x = " + formatValue(x));
  double s = 0;
  for (int k = 1; k <= n; ++k) s += std::sin(x * k) / k;
  return {{"y", s}, {"third", x / 3}, {"nested", {{"list", {x, 2 * x, "t"}}}}, {"n", n}, {"nan", NAN}};
}

SweepDescription syntheticSweep() {
  const Json j = Json::parse(R"({
    "scene": "none.json",
    "variations": [
      {"grid": [{"key": "a.x", "from": 0.1, "to": 1.0, "count": 7},
                {"key": "n", "values": [2000, 20000]}]},
      {"list": [{"a.x": 0.5, "n": 10, "fail": true}, {"a.x": 0.25, "n": 5}]}
    ],
    "collect": ["y", "third", "nested.list[1]", "nested.list[2]", "nan"]
  })");
  return SweepDescription::fromJson(j, "synthetic.json:", "");
}

}  // namespace

TEST(SweepRandom, XoshiroSequenceIsFixed) {
  // Reference values from an independent (Python) implementation of
  // splitmix64 seeding + xoshiro256**: the same on every platform.
  SweepRandom r(42);
  EXPECT_EQ(r.next(), 0x15780b2e0c2ec716ULL);
  EXPECT_EQ(r.next(), 0x6104d9866d113a7eULL);
  EXPECT_EQ(r.next(), 0xae17533239e499a1ULL);
  SweepRandom u(42);
  EXPECT_EQ(u.uniform(), 0.08386297105988216);
  EXPECT_EQ(u.uniform(), 0.3789802506626686);
  SweepRandom b(7);
  for (int i = 0; i < 1000; ++i) EXPECT_LT(b.below(3), 3u);
}

TEST(SweepVariations, GridOrderAndEndpoints) {
  const SweepDescription d = syntheticSweep();
  ASSERT_EQ(d.variations.size(), 7u * 2 + 2);
  EXPECT_EQ(d.keys, (std::vector<std::string>{"a.x", "n", "fail"}));
  // First axis slowest; the range's ends are exact.
  EXPECT_EQ(d.variations[0].id(), "a.x=0.1;n=2000");
  EXPECT_EQ(d.variations[1].id(), "a.x=0.1;n=20000");
  EXPECT_EQ(d.variations[13].find("a.x")->get<double>(), 1.0);
  EXPECT_EQ(d.variations[2].find("a.x")->get<double>(), 0.1 + 0.9 * 1.0 / 6.0);
  EXPECT_EQ(d.variations[14].id(), "a.x=0.5;fail=true;n=10");
  for (std::size_t i = 0; i < d.variations.size(); ++i) EXPECT_EQ(d.variations[i].index, i);
}

TEST(SweepVariations, LinkedKeysChangeTogether) {
  const Json j = Json::parse(R"({"scene": "s.json", "variations": [{"grid": [
      {"keys": ["tire.mu_max", "tire.mu_min"], "values": [[0.8, 0.6], [1.0, 0.75]]},
      {"key": "speed", "values": [10, 20, 30]}]}]})");
  const SweepDescription d = SweepDescription::fromJson(j, "s.json:", "");
  ASSERT_EQ(d.variations.size(), 6u);
  EXPECT_EQ(d.variations[4].id(), "tire.mu_max=1.0;tire.mu_min=0.75;speed=20");
}

TEST(SweepVariations, LatinHypercubeUsesEveryStratumOnce) {
  const int n = 50;
  const auto sets = makeLatinHypercubeVariations({{"a", 2.0, 4.0}, {"b", -1.0, 0.0}}, n, 123);
  ASSERT_EQ(sets.size(), std::size_t(n));
  for (int dim = 0; dim < 2; ++dim) {
    std::set<int> strata;
    for (const auto& s : sets) {
      const double lo = dim == 0 ? 2.0 : -1.0, hi = dim == 0 ? 4.0 : 0.0;
      const double u = (s[dim].value.get<double>() - lo) / (hi - lo);
      ASSERT_GE(u, 0.0);
      ASSERT_LT(u, 1.0);
      strata.insert(int(u * n));
    }
    EXPECT_EQ(strata.size(), std::size_t(n)) << "dimension " << dim;
  }
  // Same seed, same samples; another seed, others.
  EXPECT_EQ(makeLatinHypercubeVariations({{"a", 2.0, 4.0}}, 5, 9)[3][0].value,
            makeLatinHypercubeVariations({{"a", 2.0, 4.0}}, 5, 9)[3][0].value);
  EXPECT_NE(makeLatinHypercubeVariations({{"a", 2.0, 4.0}}, 5, 9)[3][0].value,
            makeLatinHypercubeVariations({{"a", 2.0, 4.0}}, 5, 10)[3][0].value);
}

TEST(SweepVariations, MonteCarloIsUniformInRange) {
  const auto sets = makeMonteCarloVariations({{"m", 0.5, 1.5}}, 4000, 1);
  double sum = 0;
  for (const auto& s : sets) {
    const double v = s[0].value.get<double>();
    ASSERT_GE(v, 0.5);
    ASSERT_LT(v, 1.5);
    sum += v;
  }
  // Mean of 4000 uniform samples: 1 +- 0.29/sqrt(4000) = 0.0046 (1 sigma); 5 sigma bound.
  EXPECT_NEAR(sum / 4000, 1.0, 0.023);
}

TEST(SweepFile, StrictKeysAndNamedErrors) {
  auto load = [](const char* text) {
    return errorOf([&] { SweepDescription::fromJson(Json::parse(text), "my.sweep.json:", ""); });
  };
  EXPECT_EQ(load(R"({"scene": "s.json", "variation": []})"),
            "my.sweep.json: variation: unknown key (did you mean 'variations'?); known: scene, name, set, "
            "variations, collect, output, plots");
  EXPECT_EQ(load(R"({"scene": "s.json", "variations": [{"grid": [{"key": "a", "from": 0, "to": 1, "count": -3}]}]})"),
            "my.sweep.json: variations[0].grid[0].count: expected an integer in [1, 1000000], got -3");
  EXPECT_EQ(load(R"({"scene": "s.json", "variations": [{"grid": [{"key": "a", "valuse": [1]}]}]})"),
            "my.sweep.json: variations[0].grid[0].valuse: unknown key (did you mean 'values'?); known: key, keys, "
            "values, from, to, count");
  EXPECT_EQ(load(R"({"scene": "s.json", "variations": [{"monte_carlo": {"samples": 3, "seed": 1,
                     "ranges": {"k": [2, 1]}}}]})"),
            "my.sweep.json: variations[0].monte_carlo.ranges.k: expected min < max, got [2,1]");
  EXPECT_EQ(load(R"({"scene": "s.json", "variations": [{"list": [{"a..b": 1}]}]})"),
            "my.sweep.json: variations[0].list[0]: key path 'a..b': empty part (expected e.g. a.b[2].c)");
  EXPECT_EQ(load(R"({"scene": "s.json", "variations": [{"grid": [{"key": "a", "values": [1]},
                                                               {"key": "a", "values": [2]}]}]})"),
            "my.sweep.json: variations[0].grid[1].key: key 'a' is varied twice in this block");
  EXPECT_EQ(load(R"({"scene": "s.json", "variations": [{"grid": [], "list": []}]})"),
            "my.sweep.json: variations[0]: expected exactly one of grid, list, latin_hypercube, monte_carlo, got "
            "{\"grid\":[],\"list\":[]}");
  EXPECT_EQ(load(R"({"scene": "s.json", "variations": [{"latin_hypercube": {"samples": 3, "seed": -1,
                     "ranges": {"k": [0, 1]}}}]})"),
            "my.sweep.json: variations[0].latin_hypercube.seed: expected a non-negative integer, got -1");
  EXPECT_EQ(load(R"({"variations": [{"list": [{"a": 1}]}]})"), "my.sweep.json: scene: missing key");
  EXPECT_EQ(load(R"({"scene": "s.json", "variations": [{"list": [{"a": 1}]}], "collect": ["y", "y"]})"),
            "my.sweep.json: collect[1]: 'y' is collected twice");
}

TEST(SweepRunner, ThreadsGiveTheSerialBytesAndFailedRowsKeepTheirReason) {
  const SweepDescription d = syntheticSweep();
  const std::string serialDir = tempDir("serial"), threadDir = tempDir("threads");
  SweepOptions o;
  o.out_dir = serialDir;
  const SweepResult serial = runSweep(d, synthetic, o);
  o.out_dir = threadDir;
  o.threads = 3;
  const SweepResult threaded = runSweep(d, synthetic, o);
  EXPECT_EQ(serial.workers, 1);
  EXPECT_EQ(threaded.workers, 3);
  for (const char* f : {"/results.csv", "/results.json"})
    EXPECT_EQ(readFile(serialDir + f), readFile(threadDir + f)) << f;

  const std::string csv = readFile(serialDir + "/results.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "variation,status,a.x,n,fail,y,third,nested.list[1],nested.list[2],nan,reason");
  // Row 14 failed with its reason; every variation has its row, in order.
  EXPECT_NE(csv.find("\n14,failed,0.5,10,true,,,,,,synthetic failure at a.x = 0.5\n"), std::string::npos) << csv;
  EXPECT_EQ(serial.failed, 1u);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 17);
  // Full round-trip precision: the CSV's text parses back to the very double.
  const SweepRow& r3 = serial.rows[3];
  ASSERT_TRUE(r3.ok);
  const double third = r3.values[1].get<double>();
  EXPECT_EQ(third, d.variations[3].find("a.x")->get<double>() / 3);
  EXPECT_NE(csv.find("\n3,ok," + formatSweepField(*d.variations[3].find("a.x")) + ",20000,,"), std::string::npos);
  EXPECT_EQ(std::strtod(formatSweepField(third).c_str(), nullptr), third);
  // A NaN in a summary is an empty field.
  EXPECT_TRUE(r3.values[4].is_null());
  std::filesystem::remove_all(serialDir);
  std::filesystem::remove_all(threadDir);
}

TEST(SweepRunner, MissingSummaryQuantityFailsTheRowNamingIt) {
  SweepDescription d = syntheticSweep();
  d.collect.push_back("not_there");
  SweepOptions o;
  const SweepResult r = runSweep(d, synthetic, o);
  EXPECT_FALSE(r.rows[0].ok);
  EXPECT_EQ(r.rows[0].reason.substr(0, 47), "collect: the run's summary has no 'not_there' (");
  EXPECT_EQ(r.failed, d.variations.size());
}

TEST(SweepRunner, NamedOutcomesAreRowsOfTheirOwnStatusNotFailures) {
  // A run that throws a NamedOutcome (e.g. a steady state past the fold of the
  // branch from straight running) is a row of that status in results.csv,
  // results.json, the journal and the counts, apart from the failed ones;
  // --retry-failed does not run it again.
  const SweepDescription d = syntheticSweep();
  const std::string dir = tempDir("named");
  std::atomic<int> calls{0};
  const SweepRunFunction run = [&](const SweepDescription& dd, const Variation& v) {
    ++calls;
    const double x = v.find("a.x")->get<double>();
    if (x > 0.9) throw NamedOutcome("beyond_fold", "no steady state on the branch: fold at " + formatValue(x));
    if (v.index == 2) throw NamedOutcome("past_lift_off", "past a wheel lift-off");
    return synthetic(dd, v);
  };
  SweepOptions o;
  o.out_dir = dir;
  o.threads = 2;
  const SweepResult r = runSweep(d, run, o);
  EXPECT_EQ(calls, 16);
  EXPECT_EQ(r.failed, 1u);  // row 14, the synthetic failure
  ASSERT_EQ(r.outcomes.size(), 2u);
  EXPECT_EQ(r.outcomes.at("beyond_fold"), 2u);  // a.x = 1.0 at n = 2000 and 20000
  EXPECT_EQ(r.outcomes.at("past_lift_off"), 1u);
  EXPECT_EQ(sweepStatus(r.rows[12]), "beyond_fold");
  EXPECT_EQ(sweepStatus(r.rows[14]), "failed");
  EXPECT_EQ(sweepStatus(r.rows[0]), "ok");
  const std::string csv = readFile(dir + "/results.csv");
  EXPECT_NE(csv.find("\n12,beyond_fold,"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",2000,,,,,,,no steady state on the branch: fold at "), std::string::npos) << csv;
  EXPECT_NE(csv.find("\n2,past_lift_off,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\n14,failed,"), std::string::npos) << csv;
  const Json results = Json::parse(readFile(dir + "/results.json"));
  EXPECT_EQ(results["runs"][13]["status"], "beyond_fold");
  EXPECT_EQ(results["runs"][14]["status"], "failed");
  const Json stats = Json::parse(readFile(dir + "/sweep_stats.json"));
  EXPECT_EQ(stats["failed"], 1);
  EXPECT_EQ(stats["outcomes"], Json({{"beyond_fold", 2}, {"past_lift_off", 1}}));
  // Resumed from the journal: the same statuses; --retry-failed reruns row 14 only.
  calls = 0;
  o.retry_failed = true;
  const SweepResult again = runSweep(d, run, o);
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(again.failed, 1u);
  EXPECT_EQ(again.outcomes, r.outcomes);
  EXPECT_EQ(readFile(dir + "/results.csv"), csv);
  // The progress line counts them apart.
  SweepProgress p;
  p.total = 16, p.done = 16, p.failed = 1, p.outcomes = {{"beyond_fold", 2}};
  testing::internal::CaptureStderr();
  sweepProgressPrinter("t")(p);
  EXPECT_NE(testing::internal::GetCapturedStderr().find("16/16 runs (1 failed, 2 beyond_fold)"), std::string::npos);
  EXPECT_NE(errorOf([] { NamedOutcome("beyond", "x"); }).find("unknown status 'beyond'"), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(SweepRunner, ResumeSkipsRunsInTheJournal) {
  const SweepDescription d = syntheticSweep();
  const std::string dir = tempDir("resume");
  std::atomic<int> calls{0};
  const SweepRunFunction counted = [&](const SweepDescription& dd, const Variation& v) {
    ++calls;
    return synthetic(dd, v);
  };
  SweepOptions o;
  o.out_dir = dir;
  o.threads = 2;
  runSweep(d, counted, o);
  EXPECT_EQ(calls, 16);
  const std::string full = readFile(dir + "/results.csv");

  // Everything is in the journal: nothing runs again, the outputs are the same.
  calls = 0;
  SweepResult again = runSweep(d, counted, o);
  EXPECT_EQ(calls, 0);
  EXPECT_EQ(again.resumed, 16u);
  EXPECT_EQ(readFile(dir + "/results.csv"), full);

  // A sweep killed after 10 runs, its 11th line torn by the kill: 6 runs are left.
  std::string journal = readFile(dir + "/runs.jsonl");
  std::size_t pos = 0;
  for (int k = 0; k < 10; ++k) pos = journal.find('\n', pos) + 1;
  {
    std::ofstream f(dir + "/runs.jsonl", std::ios::binary);
    f << journal.substr(0, pos) << journal.substr(pos, 25);
  }
  std::filesystem::remove(dir + "/results.csv");
  calls = 0;
  runSweep(d, counted, o);
  EXPECT_EQ(calls, 6);
  EXPECT_EQ(readFile(dir + "/results.csv"), full);

  // --retry-failed runs the failed variation again, and only it.
  calls = 0;
  o.retry_failed = true;
  runSweep(d, counted, o);
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(readFile(dir + "/results.csv"), full);

  // A journal from another sweep is refused, naming line and variation. The
  // journal is in completion order (threads), so variation 0's line is looked up.
  SweepDescription other = syntheticSweep();
  other.variations[0].settings[0].value = 0.2;
  o.retry_failed = false;
  int line0 = 0;
  {
    std::istringstream in(readFile(dir + "/runs.jsonl"));
    std::string l;
    for (int n = 1; std::getline(in, l); ++n)
      if (l.find("\"variation\":0,") != std::string::npos) {
        line0 = n;
        break;
      }
  }
  ASSERT_GT(line0, 0);
  const std::string err = errorOf([&] { runSweep(other, counted, o); });
  EXPECT_NE(err.find("runs.jsonl: line " + std::to_string(line0) +
                     ": variation 0 was 'a.x=0.1;n=2000' but the sweep now has 'a.x=0.2;n=2000'"),
            std::string::npos)
      << err;
  std::filesystem::remove_all(dir);
}

TEST(SweepFile, SummaryPathsAndPlots) {
  auto findJsonPath = [](const Json& j, const std::string& path) { return KeyPath::parse(path, "collect").find(j); };
  const Json summary = Json::parse(R"({"a": {"b": [1, {"c": 2.5}]},
                                       "plugins": [{"name": "front_steer", "x": 3}, {"name": "rear", "x": 4}]})");
  EXPECT_EQ(*findJsonPath(summary, "a.b[1].c"), 2.5);
  EXPECT_EQ(*findJsonPath(summary, "a.b.1.c"), 2.5);
  EXPECT_EQ(*findJsonPath(summary, "plugins.rear.x"), 4);
  EXPECT_EQ(findJsonPath(summary, "a.b[2]"), nullptr);
  EXPECT_EQ(findJsonPath(summary, "a.c"), nullptr);
  EXPECT_EQ(findJsonPath(summary, "plugins.middle.x"), nullptr);
  // Keys with dots (scene output names), the longest match first.
  const Json steady = Json::parse(R"({"steady": {"chassis.yaw_rate_rad_s": 0.3, "chassis": {"x": 1}},
                                      "e": {"a.b": [5, 6]}})");
  EXPECT_EQ(*findJsonPath(steady, "steady.chassis.yaw_rate_rad_s"), 0.3);
  EXPECT_EQ(*findJsonPath(steady, "steady.chassis.x"), 1);
  EXPECT_EQ(*findJsonPath(steady, "e.a.b[1]"), 6);
  EXPECT_EQ(findJsonPath(steady, "steady.chassis.y"), nullptr);

  const char* base = R"({"scene": "s.json", "variations": [{"grid": [{"key": "k", "values": [1, 2]}]}],
                         "collect": ["y"], "plots": [%s]})";
  auto load = [&](const std::string& plot) {
    char text[1024];
    std::snprintf(text, sizeof text, base, plot.c_str());
    return SweepDescription::fromJson(Json::parse(text), "p.json:", "");
  };
  const SweepDescription d = load(R"({"png": "y.png", "x": "k", "y": "y", "y_scale": 2})");
  ASSERT_EQ(d.plots.size(), 1u);
  EXPECT_EQ(d.plots[0].y_scale, 2.0);
  EXPECT_EQ(errorOf([&] { load(R"({"png": "y.png", "x": "k", "y": "z"})"); }),
            "p.json: plots[0].y: 'z' is neither a varied key nor a collected path; columns: k, y");
  EXPECT_EQ(errorOf([&] { load(R"({"png": "out/y.png", "x": "k", "y": "y"})"); }),
            "p.json: plots[0].png: expected a file name ending in .png (no folder), got \"out/y.png\"");
}

// A sweep key with an index (a steering command's steps[1]) and a collected
// path with one: both go through KeyPath (parse when the sweep is read, set by
// the --set override each run applies, find when the value is collected).
TEST(SweepFile, KeysAndCollectedPathsWithAnIndex) {
  const Json scene = R"({"plugins": [{"name": "front_steer", "command": {"steps": [{"change_rad": 0.02},
                                                                                  {"change_rad": 0.01}]}}]})"_json;
  const SweepDescription d = SweepDescription::fromJson(Json::parse(R"({"scene": "s.json",
      "variations": [{"grid": [{"key": "plugins.front_steer.command.steps[1].change_rad", "values": [0.03, 0.05]}]}],
      "collect": ["plugins.front_steer.command.steps[1].change_rad", "plugins[0].command.steps.0.change_rad"]})"),
                                                        "k.json:", "");
  const SweepResult r = runSweep(
      d,
      [&](const SweepDescription&, const Variation& v) {
        Json j = scene;
        for (const auto& st : v.settings) applyOverride(j, Override{st.key, st.value}, "s.json");
        return j;
      },
      SweepOptions{});
  ASSERT_EQ(r.rows.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    ASSERT_TRUE(r.rows[i].ok) << r.rows[i].reason;
    EXPECT_EQ(r.rows[i].values[0], i == 0 ? 0.03 : 0.05);
    EXPECT_EQ(r.rows[i].values[1], 0.02);
  }
  EXPECT_EQ(errorOf([] {
              SweepDescription::fromJson(Json::parse(R"({"scene": "s.json", "variations": [{"list": [{"a[x]": 1}]}]})"),
                                         "k.json:", "");
            }),
            "k.json: variations[0].list[0]: key path 'a[x]': index [x] is not a number (expected e.g. a.b[2].c)");
}
